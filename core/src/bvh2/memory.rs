use super::{BinaryNode, LeafWord, NodeRef};
use crate::hash::HashShape;
use core::ops::Deref;

/// Every memory read a BVH2 traversal makes goes through this trait, so that the same state
/// machine runs on slices (the CPU backend), under a traffic counter (the hardware simulator) or
/// against a deliberately corrupted copy (the conformance suite's fault injection).
pub trait BvhMemory {
    /// The internal node at `index`.
    fn node(&self, index: u32) -> BinaryNode;
    /// The internal node at `index` for reading: [`BvhMemory::node`]'s copy unless the memory
    /// can lend it in place (as [`SliceMemory`] does, so the hot loop loads only what it uses).
    #[inline(always)]
    fn read_node(&self, index: u32) -> MemRead<'_, BinaryNode> {
        MemRead::Copied(self.node(index))
    }
    /// The leaf entry at `offset`.
    fn leaf_word(&self, offset: u32) -> LeafWord;
    /// The leaf entry at `offset` for reading: [`BvhMemory::leaf_word`]'s copy unless the memory
    /// can lend it in place (see [`BvhMemory::read_node`]).
    #[inline(always)]
    fn read_leaf_word(&self, offset: u32) -> MemRead<'_, LeafWord> {
        MemRead::Copied(self.leaf_word(offset))
    }
    /// Perfect-hash displacement entry `slot` (Binder & Keller 2016, Sec. 2.2.1).
    fn displacement(&self, slot: u32) -> i32;
    /// Perfect-hash table cell `slot`.
    fn hash_cell(&self, slot: u32) -> u32;
    /// Sizes of the hash tables (a constant of the scene).
    fn hash_shape(&self) -> HashShape;

    /// The first two links of a node (internal: its link slots; leaf: the free slots of its
    /// first triangle), read without searching for a leaf's terminator.
    #[inline(always)]
    fn hop_links(&self, r: NodeRef) -> [NodeRef; 2] {
        if r.is_leaf() {
            [self.leaf_word(r.offset() + 1).slot_link(), self.leaf_word(r.offset() + 2).slot_link()]
        } else {
            self.read_node(r.index()).links
        }
    }
}

/// A record as [`BvhMemory::read_node`] and [`BvhMemory::read_leaf_word`] hand it out: borrowed
/// where the memory holds it, or copied; read alike through `Deref`.
#[derive(Clone, Copy, Debug)]
pub enum MemRead<'a, T> {
    /// The record where the memory holds it.
    InPlace(&'a T),
    /// A copy.
    Copied(T),
}

impl<T> Deref for MemRead<'_, T> {
    type Target = T;

    #[inline(always)]
    fn deref(&self) -> &T {
        match self {
            MemRead::InPlace(record) => record,
            MemRead::Copied(record) => record,
        }
    }
}

/// Node data and hash tables in plain slices: the CPU backend's memory.
#[derive(Clone, Copy, Debug)]
pub struct SliceMemory<'a> {
    /// Internal nodes.
    pub nodes: &'a [BinaryNode],
    /// Leaf entries.
    pub leaves: &'a [LeafWord],
    /// Displacement table (empty when the scene has no hash).
    pub displacement: &'a [i32],
    /// Hash table cells.
    pub cells: &'a [u32],
    /// Table sizes.
    pub shape: HashShape,
}

impl BvhMemory for SliceMemory<'_> {
    #[inline(always)]
    fn node(&self, index: u32) -> BinaryNode {
        self.nodes[index as usize]
    }
    #[inline(always)]
    fn read_node(&self, index: u32) -> MemRead<'_, BinaryNode> {
        MemRead::InPlace(&self.nodes[index as usize])
    }
    #[inline(always)]
    fn read_leaf_word(&self, offset: u32) -> MemRead<'_, LeafWord> {
        MemRead::InPlace(&self.leaves[offset as usize])
    }
    #[inline(always)]
    fn leaf_word(&self, offset: u32) -> LeafWord {
        self.leaves[offset as usize]
    }
    #[inline(always)]
    fn displacement(&self, slot: u32) -> i32 {
        self.displacement[slot as usize]
    }
    #[inline(always)]
    fn hash_cell(&self, slot: u32) -> u32 {
        self.cells[slot as usize]
    }
    #[inline(always)]
    fn hash_shape(&self) -> HashShape {
        self.shape
    }
}
