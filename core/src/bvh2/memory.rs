use super::{BinaryNode, LeafWord};

/// Every memory read a BVH2 traversal makes goes through this trait, so that the same state
/// machine runs on slices (the CPU backend), under a traffic counter (the hardware simulator) or
/// against a deliberately corrupted copy (the conformance suite's fault injection).
pub trait BvhMemory {
    /// The internal node at `index`.
    fn node(&self, index: u32) -> BinaryNode;
    /// The leaf entry at `offset`.
    fn leaf_word(&self, offset: u32) -> LeafWord;
    /// Perfect-hash displacement entry `slot` (Binder & Keller 2016, Sec. 2.2.1).
    fn displacement(&self, slot: u32) -> i32;
    /// Perfect-hash table cell `slot`.
    fn hash_cell(&self, slot: u32) -> u32;
}
