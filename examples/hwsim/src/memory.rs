//! Memory traffic: wrappers over each structure's memory trait ([`BvhMemory`], [`KdMemory`],
//! [`WideMemory`]) that count every read and the cache lines it touches.

use raytrail_core::bvh2::{BinaryNode, BvhMemory, LeafWord, MemRead};
use raytrail_core::glam::Vec3;
use raytrail_core::hash::HashShape;
use raytrail_core::intersect::TriangleBlock;
use raytrail_core::kd::{KdMemory, KdNode};
use raytrail_core::wide::{WideMemory, WideNode};
use std::cell::{Cell, RefCell};

/// Bytes of a cache line (and of a coalesced memory transaction, roughly).
pub const LINE_BYTES: u64 = 64;

/// The tables the traversals read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Table {
    /// BVH2 internal nodes, 64 bytes each.
    Nodes,
    /// BVH2 leaf words (a triangle's vertex, a terminator), 16 bytes each.
    LeafWords,
    /// Perfect-hash displacement entries, 4 bytes each.
    Displacement,
    /// Perfect-hash cells, 4 bytes each.
    HashCells,
    /// kd-tree nodes, 8 bytes each.
    KdNodes,
    /// kd leaves' primitive references, 4 bytes each.
    PrimRefs,
    /// Triangles by primitive id (kd) or position (wide, one at a time), 36 bytes each.
    Triangles,
    /// Wide-BVH nodes, `32 W` bytes each.
    WideNodes,
    /// Wide-BVH triangles in blocks of four, 144 bytes each.
    TriangleBlocks,
    /// Wide-BVH primitive ids by triangle position, 4 bytes each.
    PrimIds,
}

impl Table {
    /// Every table, in the order of [`Traffic::reads`].
    pub const ALL: [Table; 10] = [
        Table::Nodes,
        Table::LeafWords,
        Table::Displacement,
        Table::HashCells,
        Table::KdNodes,
        Table::PrimRefs,
        Table::Triangles,
        Table::WideNodes,
        Table::TriangleBlocks,
        Table::PrimIds,
    ];

    /// Short name, as printed.
    pub const fn name(self) -> &'static str {
        match self {
            Table::Nodes => "node",
            Table::LeafWords => "leaf",
            Table::Displacement => "disp",
            Table::HashCells => "cell",
            Table::KdNodes => "kd node",
            Table::PrimRefs => "ref",
            Table::Triangles => "tri",
            Table::WideNodes => "wide node",
            Table::TriangleBlocks => "block",
            Table::PrimIds => "id",
        }
    }
}

/// Reads, bytes and cache lines, summed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Traffic {
    /// Reads per table, in the order of [`Table::ALL`].
    pub reads: [u64; 10],
    /// Bytes read per table, in the same order.
    pub bytes: [u64; 10],
    /// Distinct cache lines touched, summed over warp-steps: each warp-step counts a line once,
    /// however many of its lanes read it (the coalescing a SIMT memory unit would do).
    pub lines: u64,
}

impl Traffic {
    /// Bytes read from `table`.
    pub fn bytes(&self, table: Table) -> u64 {
        self.bytes[table as usize]
    }

    /// Bytes read from every table.
    pub fn total_bytes(&self) -> u64 {
        self.bytes.iter().sum()
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
        for (a, b) in self.bytes.iter_mut().zip(o.bytes) {
            *a += b;
        }
        self.lines += o.lines;
    }
}

/// The counters every counting memory shares: reads and bytes per table, and the lines touched
/// in the current warp-step. In cells because the memory traits read through `&self`.
///
/// Each table is taken to start on a line boundary in its own address range, so a 64-byte node is
/// one line, four consecutive leaf words share one, sixteen 4-byte entries share one, and a
/// 128-byte wide node spans two.
#[derive(Debug, Default)]
pub struct ReadTally {
    reads: [Cell<u64>; 10],
    bytes: [Cell<u64>; 10],
    /// Lines touched in the current warp-step: table in the top byte, line index below.
    lines: RefCell<Vec<u64>>,
    lines_total: Cell<u64>,
}

impl ReadTally {
    /// Counts a read of record `index` of `table`, records of `record_bytes` each.
    #[inline]
    pub fn touch(&self, table: Table, index: u32, record_bytes: u64) {
        let t = table as usize;
        self.reads[t].set(self.reads[t].get() + 1);
        self.bytes[t].set(self.bytes[t].get() + record_bytes);
        let first = u64::from(index) * record_bytes;
        let mut lines = self.lines.borrow_mut();
        for line in first / LINE_BYTES..=(first + record_bytes.max(1) - 1) / LINE_BYTES {
            lines.push(((table as u64) << 56) | line);
        }
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
        Traffic {
            reads: self.reads.each_ref().map(Cell::get),
            bytes: self.bytes.each_ref().map(Cell::get),
            lines: self.lines_total.get(),
        }
    }

    /// Reads of `table` so far.
    pub fn reads(&self, table: Table) -> u64 {
        self.reads[table as usize].get()
    }
}

/// A [`BvhMemory`] that counts reads per table and the cache lines they touch.
#[derive(Debug)]
pub struct CountingMemory<M: BvhMemory> {
    inner: M,
    tally: ReadTally,
}

impl<M: BvhMemory> CountingMemory<M> {
    /// Counts reads of `inner`, from zero.
    pub fn new(inner: M) -> Self {
        Self { inner, tally: ReadTally::default() }
    }

    /// The wrapped memory (reads through it are not counted).
    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// The counters.
    pub fn tally(&self) -> &ReadTally {
        &self.tally
    }

    /// Ends a warp-step ([`ReadTally::end_cycle`]).
    pub fn end_cycle(&self) -> u64 {
        self.tally.end_cycle()
    }

    /// What has been read so far.
    pub fn traffic(&self) -> Traffic {
        self.tally.traffic()
    }

    /// Reads of the hash tables so far (displacement and cells).
    pub fn hash_reads(&self) -> u64 {
        self.tally.reads(Table::Displacement) + self.tally.reads(Table::HashCells)
    }
}

impl<M: BvhMemory> BvhMemory for CountingMemory<M> {
    fn node(&self, index: u32) -> BinaryNode {
        self.tally.touch(Table::Nodes, index, 64);
        self.inner.node(index)
    }
    fn leaf_word(&self, offset: u32) -> LeafWord {
        self.tally.touch(Table::LeafWords, offset, 16);
        self.inner.leaf_word(offset)
    }
    fn displacement(&self, slot: u32) -> i32 {
        self.tally.touch(Table::Displacement, slot, 4);
        self.inner.displacement(slot)
    }
    fn hash_cell(&self, slot: u32) -> u32 {
        self.tally.touch(Table::HashCells, slot, 4);
        self.inner.hash_cell(slot)
    }
    /// A scene constant (held in registers), not a read.
    fn hash_shape(&self) -> HashShape {
        self.inner.hash_shape()
    }
    // `hop_links` keeps the trait's default, which reads through the counted methods above.
}

/// A [`KdMemory`] that counts reads: nodes (8 B), primitive references (4 B) and triangles (36 B).
#[derive(Debug)]
pub struct CountingKdMemory<M: KdMemory> {
    inner: M,
    tally: ReadTally,
}

impl<M: KdMemory> CountingKdMemory<M> {
    /// Counts reads of `inner`, from zero.
    pub fn new(inner: M) -> Self {
        Self { inner, tally: ReadTally::default() }
    }

    /// The wrapped memory (reads through it are not counted).
    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// The counters.
    pub fn tally(&self) -> &ReadTally {
        &self.tally
    }
}

impl<M: KdMemory> KdMemory for CountingKdMemory<M> {
    fn kd_node(&self, index: u32) -> KdNode {
        self.tally.touch(Table::KdNodes, index, 8);
        self.inner.kd_node(index)
    }
    fn prim_ref(&self, i: u32) -> u32 {
        self.tally.touch(Table::PrimRefs, i, 4);
        self.inner.prim_ref(i)
    }
    fn triangle(&self, prim: u32) -> [Vec3; 3] {
        self.tally.touch(Table::Triangles, prim, 36);
        self.inner.triangle(prim)
    }
    // `read_triangle` keeps the trait's default: a counted `triangle`.
}

/// A [`WideMemory`] that counts reads: nodes (`32 W` B), primitive ids (4 B), single triangles
/// (36 B) and blocks of four (144 B).
#[derive(Debug)]
pub struct CountingWideMemory<M> {
    inner: M,
    tally: ReadTally,
}

impl<M> CountingWideMemory<M> {
    /// Counts reads of `inner`, from zero.
    pub fn new(inner: M) -> Self {
        Self { inner, tally: ReadTally::default() }
    }

    /// The wrapped memory (reads through it are not counted).
    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// The counters.
    pub fn tally(&self) -> &ReadTally {
        &self.tally
    }

    /// Reads of the hash tables so far (displacement and cells: the stackless walk's lookups).
    pub fn hash_reads(&self) -> u64 {
        self.tally.reads(Table::Displacement) + self.tally.reads(Table::HashCells)
    }
}

impl<const W: usize, M: WideMemory<W>> WideMemory<W> for CountingWideMemory<M> {
    fn wide_node(&self, index: u32) -> MemRead<'_, WideNode<W>> {
        self.tally.touch(Table::WideNodes, index, 32 * W as u64);
        self.inner.wide_node(index)
    }
    fn prim(&self, pos: u32) -> u32 {
        self.tally.touch(Table::PrimIds, pos, 4);
        self.inner.prim(pos)
    }
    fn wide_triangle(&self, pos: u32) -> MemRead<'_, [Vec3; 3]> {
        self.tally.touch(Table::Triangles, pos, 36);
        self.inner.wide_triangle(pos)
    }
    fn wide_block(&self, index: u32) -> MemRead<'_, TriangleBlock> {
        self.tally.touch(Table::TriangleBlocks, index, 144);
        self.inner.wide_block(index)
    }
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
        assert_eq!(t.reads[..4], [3, 5, 0, 3]);
        assert_eq!(t.total_bytes(), 3 * 64 + 5 * 16 + 3 * 4);
        assert_eq!(t.lines, 6);
    }

    #[test]
    fn a_record_wider_than_a_line_touches_every_line_it_spans() {
        let tally = ReadTally::default();
        // 144-byte blocks: block 0 spans lines 0-2, block 1 lines 2-4.
        tally.touch(Table::TriangleBlocks, 0, 144);
        tally.touch(Table::TriangleBlocks, 1, 144);
        assert_eq!(tally.end_cycle(), 5);
        assert_eq!(tally.traffic().bytes(Table::TriangleBlocks), 288);
    }
}
