use bytemuck::{Pod, Zeroable};

/// A kd-tree node in 8 bytes (Horn et al. 2007 keep one word per splitting plane; the second word
/// addresses children or primitives):
/// - inner node: `value` is the split position; `word` holds the axis (0, 1, 2) in its two low
///   bits and the index of the child below the plane above them (the child above is next to it);
/// - leaf: `value` holds the primitive count as bits; `word` holds 3 in its low bits and the first
///   entry of the primitive-reference array above them.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct KdNode {
    /// Split position (inner) or primitive count as `u32` bits (leaf).
    pub value: f32,
    /// Axis or leaf tag in bits 0-1; child index or first primitive reference above.
    pub word: u32,
}

impl KdNode {
    const LEAF: u32 = 3;
    /// Largest child index or primitive-reference offset, exclusive.
    pub const LIMIT: u32 = 1 << 30;

    /// An inner node splitting `axis` at `split`, children at `below` and `below + 1`.
    pub fn inner(axis: usize, split: f32, below: u32) -> KdNode {
        KdNode { value: split, word: (below << 2) | axis as u32 }
    }

    /// A leaf of `count` references starting at `first`.
    pub fn leaf(first: u32, count: u32) -> KdNode {
        KdNode { value: f32::from_bits(count), word: (first << 2) | Self::LEAF }
    }

    /// Whether this is a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.word & 3 == Self::LEAF
    }

    /// Split axis of an inner node.
    #[inline(always)]
    pub fn axis(&self) -> usize {
        (self.word & 3) as usize
    }

    /// Index of the child below the plane (the one above is the next index).
    #[inline(always)]
    pub fn below(&self) -> u32 {
        self.word >> 2
    }

    /// First primitive reference of a leaf.
    #[inline(always)]
    pub fn first(&self) -> u32 {
        self.word >> 2
    }

    /// Number of primitives in a leaf.
    #[inline(always)]
    pub fn count(&self) -> u32 {
        self.value.to_bits()
    }
}
