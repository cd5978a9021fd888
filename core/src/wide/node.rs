use crate::bvh2::NodeRef;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// The child slot that holds nothing. Its box is empty (`lo = +inf`, `hi = -inf`), which every
/// slab test misses, so traversal needs no separate check for it.
pub const EMPTY_CHILD: u32 = u32::MAX;

/// A node of a `W`-wide BVH, laid out for testing all children at once: the child boxes as a
/// structure of arrays (one array of `W` floats per box plane), then the child references. The
/// builder fills the slots from 0, largest box first (the order any-hit queries visit them in).
///
/// Byte layout (`repr(C)`, no padding, `32 W` bytes; the WGSL kernels read it as `8 W` words):
///
/// | offset | field | meaning |
/// |---|---|---|
/// | `0` | `lo[0..3][W]` | lower box corners: all children's x, then y, then z |
/// | `12 W` | `hi[0..3][W]` | upper box corners, likewise |
/// | `24 W` | `child[W]` | an internal child's node index; a leaf's first triangle position; [`EMPTY_CHILD`] |
/// | `28 W` | `count[W]` | a leaf's triangle count; 0 for an internal child or an empty slot |
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct WideNode<const W: usize> {
    /// Lower corners of the child boxes, by axis.
    pub lo: [[f32; W]; 3],
    /// Upper corners of the child boxes, by axis.
    pub hi: [[f32; W]; 3],
    /// Child references (see the table above).
    pub child: [u32; W],
    /// Leaf triangle counts (0: not a leaf).
    pub count: [u32; W],
}

// SAFETY: `repr(C)` of arrays of `f32` and `u32` only, all 4-byte aligned, so there is no padding
// and every bit pattern is a valid value.
unsafe impl<const W: usize> Zeroable for WideNode<W> {}
// SAFETY: as above; the type is `Copy + 'static`.
unsafe impl<const W: usize> Pod for WideNode<W> {}

impl<const W: usize> WideNode<W> {
    /// A node whose every slot is empty.
    pub const EMPTY: WideNode<W> = WideNode {
        lo: [[f32::INFINITY; W]; 3],
        hi: [[f32::NEG_INFINITY; W]; 3],
        child: [EMPTY_CHILD; W],
        count: [0; W],
    };

    /// The box of child slot `i`.
    #[inline(always)]
    pub fn child_box(&self, i: usize) -> (Vec3, Vec3) {
        (Vec3::new(self.lo[0][i], self.lo[1][i], self.lo[2][i]), Vec3::new(self.hi[0][i], self.hi[1][i], self.hi[2][i]))
    }

    /// Sets child slot `i`.
    pub fn set_child(&mut self, i: usize, lo: Vec3, hi: Vec3, child: WideChild) {
        for a in 0..3 {
            self.lo[a][i] = lo[a];
            self.hi[a][i] = hi[a];
        }
        (self.child[i], self.count[i]) = child.words();
    }

    /// What child slot `i` refers to, or `None` for an empty slot (or a slot past `W`).
    #[inline(always)]
    pub fn child_ref(&self, i: usize) -> Option<WideChild> {
        WideChild::from_words(*self.child.get(i)?, self.count[i])
    }
}

/// What a child slot refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WideChild {
    /// An internal node, by index.
    Node(u32),
    /// A leaf: `count` triangles from position `first` of the tree's triangle array.
    Leaf {
        /// First triangle position.
        first: u32,
        /// Number of triangles (at least 1).
        count: u32,
    },
}

impl WideChild {
    /// What a slot holding `child` and `count` refers to (see [`WideNode`]'s layout), or `None`
    /// for an empty slot.
    #[inline(always)]
    pub fn from_words(child: u32, count: u32) -> Option<WideChild> {
        match (child, count) {
            (EMPTY_CHILD, _) => None,
            (n, 0) => Some(WideChild::Node(n)),
            (first, count) => Some(WideChild::Leaf { first, count }),
        }
    }

    /// The slot words (`child`, `count`) that hold this child: [`WideChild::from_words`]'s
    /// inverse.
    #[inline(always)]
    pub fn words(self) -> (u32, u32) {
        match self {
            WideChild::Node(n) => (n, 0),
            WideChild::Leaf { first, count } => (first, count),
        }
    }

    /// The reference an observer records for this child: [`NodeRef::internal`] of the node index,
    /// or [`NodeRef::leaf`] of the first triangle position.
    #[inline(always)]
    pub fn node_ref(self) -> NodeRef {
        match self {
            WideChild::Node(n) => NodeRef::internal(n),
            WideChild::Leaf { first, .. } => NodeRef::leaf(first),
        }
    }
}
