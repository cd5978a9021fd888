//! Memory traffic: a [`BvhMemory`] wrapper that counts every read and the cache lines it touches.

use raytrail_core::bvh2::{BinaryNode, BvhMemory, LeafWord};
use raytrail_core::hash::HashShape;
use std::cell::{Cell, RefCell};

/// Bytes of a cache line (and of a coalesced memory transaction, roughly).
pub const LINE_BYTES: u64 = 64;

/// The tables a BVH2 traversal reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Table {
    /// Internal nodes, 64 bytes each.
    Nodes,
    /// Leaf words (a triangle's vertex, a terminator), 16 bytes each.
    LeafWords,
    /// Perfect-hash displacement entries, 4 bytes each.
    Displacement,
    /// Perfect-hash cells, 4 bytes each.
    HashCells,
}

impl Table {
    /// Every table, in the order of [`Traffic::reads`].
    pub const ALL: [Table; 4] = [Table::Nodes, Table::LeafWords, Table::Displacement, Table::HashCells];

    /// Bytes of one record (one read).
    pub const fn record_bytes(self) -> u64 {
        match self {
            Table::Nodes => 64,
            Table::LeafWords => 16,
            Table::Displacement | Table::HashCells => 4,
        }
    }

    /// Short name, as printed.
    pub const fn name(self) -> &'static str {
        match self {
            Table::Nodes => "nodes",
            Table::LeafWords => "leaf words",
            Table::Displacement => "displacement",
            Table::HashCells => "hash cells",
        }
    }
}

/// Reads and cache lines, summed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Traffic {
    /// Reads per table, in the order of [`Table::ALL`].
    pub reads: [u64; 4],
    /// Distinct cache lines touched, summed over warp-steps: each warp-step counts a line once,
    /// however many of its lanes read it (the coalescing a SIMT memory unit would do).
    pub lines: u64,
}

impl Traffic {
    /// Bytes read from `table`.
    pub fn bytes(&self, table: Table) -> u64 {
        self.reads[table as usize] * table.record_bytes()
    }

    /// Bytes read from every table.
    pub fn total_bytes(&self) -> u64 {
        Table::ALL.iter().map(|&t| self.bytes(t)).sum()
    }

    /// Reads from every table.
    pub fn total_reads(&self) -> u64 {
        self.reads.iter().sum()
    }

    /// Adds another tally.
    pub fn add(&mut self, o: &Traffic) {
        for (a, b) in self.reads.iter_mut().zip(o.reads) {
            *a += b;
        }
        self.lines += o.lines;
    }
}

/// A [`BvhMemory`] that counts reads per table and collects the cache lines they touch until
/// [`CountingMemory::end_cycle`].
///
/// Each table is taken to start on a line boundary in its own address range, so a node is one
/// line, four consecutive leaf words share one, and sixteen hash entries share one. Counters sit
/// in cells because the trait reads through `&self`.
#[derive(Debug)]
pub struct CountingMemory<M: BvhMemory> {
    inner: M,
    reads: [Cell<u64>; 4],
    /// Lines touched in the current warp-step: table in the top byte, line index below.
    lines: RefCell<Vec<u64>>,
    lines_total: Cell<u64>,
}

impl<M: BvhMemory> CountingMemory<M> {
    /// Counts reads of `inner`, from zero.
    pub fn new(inner: M) -> Self {
        Self { inner, reads: Default::default(), lines: RefCell::new(Vec::new()), lines_total: Cell::new(0) }
    }

    /// The wrapped memory (reads through it are not counted).
    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// Ends a warp-step: returns the number of distinct lines its reads touched and starts the
    /// next step's set empty.
    pub fn end_cycle(&self) -> u64 {
        let mut lines = self.lines.borrow_mut();
        lines.sort_unstable();
        lines.dedup();
        let n = lines.len() as u64;
        lines.clear();
        self.lines_total.set(self.lines_total.get() + n);
        n
    }

    /// What has been read so far (lines: only those of finished warp-steps).
    pub fn traffic(&self) -> Traffic {
        Traffic { reads: self.reads.each_ref().map(Cell::get), lines: self.lines_total.get() }
    }

    /// Reads of the hash tables so far (displacement and cells).
    pub fn hash_reads(&self) -> u64 {
        self.reads[Table::Displacement as usize].get() + self.reads[Table::HashCells as usize].get()
    }

    #[inline]
    fn touch(&self, table: Table, index: u32) {
        let c = &self.reads[table as usize];
        c.set(c.get() + 1);
        let line = u64::from(index) * table.record_bytes() / LINE_BYTES;
        self.lines.borrow_mut().push(((table as u64) << 56) | line);
    }
}

impl<M: BvhMemory> BvhMemory for CountingMemory<M> {
    fn node(&self, index: u32) -> BinaryNode {
        self.touch(Table::Nodes, index);
        self.inner.node(index)
    }
    fn leaf_word(&self, offset: u32) -> LeafWord {
        self.touch(Table::LeafWords, offset);
        self.inner.leaf_word(offset)
    }
    fn displacement(&self, slot: u32) -> i32 {
        self.touch(Table::Displacement, slot);
        self.inner.displacement(slot)
    }
    fn hash_cell(&self, slot: u32) -> u32 {
        self.touch(Table::HashCells, slot);
        self.inner.hash_cell(slot)
    }
    /// A scene constant (held in registers), not a read.
    fn hash_shape(&self) -> HashShape {
        self.inner.hash_shape()
    }
    // `hop_links` keeps the trait's default, which reads through the counted methods above.
}

#[cfg(test)]
mod tests {
    use super::*;
    use bytemuck::Zeroable;
    use raytrail_core::bvh2::{NodeRef, SliceMemory};

    #[test]
    fn counts_reads_and_distinct_lines() {
        let nodes = [BinaryNode::zeroed(); 4];
        let leaves = [LeafWord::terminator([NodeRef::NONE; 3]); 8];
        let cells = [0u32; 32];
        let inner = SliceMemory {
            nodes: &nodes,
            leaves: &leaves,
            displacement: &[0; 4],
            cells: &cells,
            shape: HashShape::default(),
        };
        let m = CountingMemory::new(inner);
        m.node(1);
        m.node(1);
        m.node(2);
        // Leaf words 0..=3 share a line; 4 starts the next.
        for o in 0..5 {
            m.leaf_word(o);
        }
        m.hash_cell(0);
        m.hash_cell(15);
        m.hash_cell(16);
        assert_eq!(m.end_cycle(), 2 + 2 + 2);
        assert_eq!(m.end_cycle(), 0);
        let t = m.traffic();
        assert_eq!(t.reads, [3, 5, 0, 3]);
        assert_eq!(t.total_bytes(), 3 * 64 + 5 * 16 + 3 * 4);
        assert_eq!(t.lines, 6);
    }
}
