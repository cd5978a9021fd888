use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// A reference to a node of a [`BinaryLayout`](super::BinaryLayout), as stored in child and link
/// slots (Aila & Laine 2009; Binder & Keller 2016, Sec. 2.2.2).
///
/// - an internal node: its index, below `2^30`;
/// - a leaf: the bitwise complement of its offset in the leaf array (`!offset`, at or above
///   `0xC000_0000`), so the sign bit tells leaves apart;
/// - [`NodeRef::NONE`]: no node (an absent link), which is neither.
///
/// The gap between `2^30` and `0xC000_0000` is what lets a displacement entry hold an internal
/// address directly, shifted by `0x8000_0000`, without clashing with leaf references.
#[repr(transparent)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct NodeRef(pub u32);

impl NodeRef {
    /// No node.
    pub const NONE: NodeRef = NodeRef(0x7FFF_FFFF);
    /// Largest internal index or leaf offset, exclusive.
    pub const LIMIT: u32 = 1 << 30;

    /// An internal node by index.
    #[inline(always)]
    pub const fn internal(index: u32) -> NodeRef {
        NodeRef(index)
    }

    /// A leaf by offset into the leaf array.
    #[inline(always)]
    pub const fn leaf(offset: u32) -> NodeRef {
        NodeRef(!offset)
    }

    /// Whether this is a leaf.
    #[inline(always)]
    pub const fn is_leaf(self) -> bool {
        self.0 >= 0xC000_0000
    }

    /// Whether this is [`NodeRef::NONE`].
    #[inline(always)]
    pub const fn is_none(self) -> bool {
        self.0 == Self::NONE.0
    }

    /// Index of an internal node.
    #[inline(always)]
    pub const fn index(self) -> u32 {
        self.0
    }

    /// Offset of a leaf.
    #[inline(always)]
    pub const fn offset(self) -> u32 {
        !self.0
    }
}

/// An internal node in the Aila-Laine layout (64 bytes): the boxes of both children, packed as
/// in their CUDA kernels, the two child references, and two link slots that the stack method
/// leaves as padding and the stackless methods fill with uncle and grand-uncle (or parent and
/// sibling) references (Binder & Keller 2016, Fig. 4).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct BinaryNode {
    /// Left child `lo.x, hi.x, lo.y, hi.y`.
    pub left_xy: [f32; 4],
    /// Right child `lo.x, hi.x, lo.y, hi.y`.
    pub right_xy: [f32; 4],
    /// Left child `lo.z, hi.z`, then right child `lo.z, hi.z`.
    pub z: [f32; 4],
    /// Left and right child.
    pub children: [NodeRef; 2],
    /// Uncle and grand uncle, or parent and sibling, of this node ([`super::LinkKind`]).
    pub links: [NodeRef; 2],
}

impl BinaryNode {
    /// Bounds of child `i` (0: left, 1: right) as `(lo, hi)`.
    #[inline(always)]
    pub fn child_bounds(&self, i: usize) -> (Vec3, Vec3) {
        let xy = if i == 0 { &self.left_xy } else { &self.right_xy };
        let z = &self.z[2 * i..2 * i + 2];
        (Vec3::new(xy[0], xy[2], z[0]), Vec3::new(xy[1], xy[3], z[1]))
    }
}

/// One 16-byte entry of the leaf array (Aila & Laine's `float4`).
///
/// A leaf is a run of triangles, three entries each, closed by a termination entry
/// (Binder & Keller 2016, Fig. 5):
/// - triangle entry 0: `v0.xyz` and the primitive id; entries 1 and 2: `v1.xyz`, `v2.xyz` and, in
///   the leaf's first triangle, the leaf's first two links (0 in later triangles);
/// - termination entry: three link references and [`LeafWord::TERMINATOR`] in the last slot.
///
/// The marker sits in the slot that holds the primitive id, not in `x` as in Aila & Laine, because
/// a vertex coordinate of `-0.0` has the bit pattern `0x8000_0000` of their marker.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct LeafWord(pub [u32; 4]);

impl LeafWord {
    /// Marker in the last slot of the entry closing a leaf (primitive ids are below it).
    pub const TERMINATOR: u32 = u32::MAX;

    /// Whether this entry closes its leaf.
    #[inline(always)]
    pub fn is_terminator(&self) -> bool {
        self.0[3] == Self::TERMINATOR
    }

    /// The vertex stored in a triangle entry.
    #[inline(always)]
    pub fn vertex(&self) -> Vec3 {
        Vec3::new(f32::from_bits(self.0[0]), f32::from_bits(self.0[1]), f32::from_bits(self.0[2]))
    }

    /// The vertex stored in a triangle entry, read in place.
    #[inline(always)]
    pub fn vertex_ref(&self) -> &[f32; 3] {
        let slots: &[f32; 4] = bytemuck::cast_ref(&self.0);
        slots.first_chunk().expect("an entry has four slots")
    }

    /// The primitive id of a triangle's first entry (or the link in entries 1 and 2).
    #[inline(always)]
    pub fn prim(&self) -> u32 {
        self.0[3]
    }

    /// The link held in the free slot of a leaf's first triangle's entry 1 or 2.
    #[inline(always)]
    pub fn slot_link(&self) -> NodeRef {
        NodeRef(self.0[3])
    }

    /// The three link references of a termination entry.
    #[inline(always)]
    pub fn links(&self) -> [NodeRef; 3] {
        [NodeRef(self.0[0]), NodeRef(self.0[1]), NodeRef(self.0[2])]
    }

    /// A triangle entry: a vertex and the slot value (primitive id in entry 0, else 0).
    pub fn vertex_entry(v: Vec3, slot: u32) -> Self {
        LeafWord([v.x.to_bits(), v.y.to_bits(), v.z.to_bits(), slot])
    }

    /// A termination entry carrying three links.
    pub fn terminator(links: [NodeRef; 3]) -> Self {
        LeafWord([links[0].0, links[1].0, links[2].0, Self::TERMINATOR])
    }
}
