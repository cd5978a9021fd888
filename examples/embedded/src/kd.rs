//! The kd-tree in flash: [`KdMemory`] over the baked nodes, primitive references and triangles.

use raytrail_core::glam::Vec3;
use raytrail_core::kd::{KdMemory, KdNode};

/// A leaf with no primitives: reading past the node table ends that path instead of indexing
/// out of bounds.
const INERT_KD_NODE: KdNode = KdNode { value: 0.0, word: 3 };

/// A triangle no ray hits (every vertex NaN): what a read past the triangle table returns.
const INERT_TRIANGLE: [Vec3; 3] = [Vec3::NAN; 3];

/// [`KdMemory`] over tables in flash; reads outside a table return inert values (an empty leaf,
/// primitive 0's reference, a NaN triangle) rather than panicking.
#[derive(Clone, Copy, Debug)]
pub struct KdFlashMemory<'a> {
    pub(crate) nodes: &'a [KdNode],
    pub(crate) prims: &'a [u32],
    pub(crate) triangles: &'a [[Vec3; 3]],
}

impl KdMemory for KdFlashMemory<'_> {
    #[inline(always)]
    fn kd_node(&self, index: u32) -> KdNode {
        self.nodes.get(index as usize).copied().unwrap_or(INERT_KD_NODE)
    }
    #[inline(always)]
    fn prim_ref(&self, i: u32) -> u32 {
        self.prims.get(i as usize).copied().unwrap_or(u32::MAX)
    }
    #[inline(always)]
    fn triangle(&self, prim: u32) -> [Vec3; 3] {
        self.triangles.get(prim as usize).copied().unwrap_or(INERT_TRIANGLE)
    }
}
