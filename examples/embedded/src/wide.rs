//! The 4-wide BVH in flash: [`WideMemory`] over the baked nodes, triangle blocks and primitive ids.

use raytrail_core::bvh2::MemRead;
use raytrail_core::glam::Vec3;
use raytrail_core::intersect::{TriangleBlock, BLOCK};
use raytrail_core::wide::{WideMemory, WideNode};

/// A block whose triangles no ray hits (every coordinate NaN).
const INERT_BLOCK: TriangleBlock = TriangleBlock { v: [[[f32::NAN; BLOCK]; 3]; 3] };

/// [`WideMemory`] over tables in flash. The triangles are stored once, in blocks of four (what the
/// traversal reads); a single triangle is copied out of its block. Reads outside a table return
/// inert values (a node of empty slots, a NaN triangle) rather than panicking.
#[derive(Clone, Copy, Debug)]
pub struct WideFlashMemory<'a> {
    pub(crate) nodes: &'a [WideNode<4>],
    pub(crate) blocks: &'a [TriangleBlock],
    pub(crate) prims: &'a [u32],
}

impl WideMemory<4> for WideFlashMemory<'_> {
    #[inline(always)]
    fn wide_node(&self, index: u32) -> MemRead<'_, WideNode<4>> {
        match self.nodes.get(index as usize) {
            Some(n) => MemRead::InPlace(n),
            None => MemRead::Copied(WideNode::EMPTY),
        }
    }
    #[inline(always)]
    fn prim(&self, pos: u32) -> u32 {
        self.prims.get(pos as usize).copied().unwrap_or(u32::MAX)
    }
    #[inline(always)]
    fn wide_triangle(&self, pos: u32) -> MemRead<'_, [Vec3; 3]> {
        let b = self.blocks.get(pos as usize / BLOCK).unwrap_or(&INERT_BLOCK);
        MemRead::Copied(b.lane(pos as usize % BLOCK).map(Vec3::from_array))
    }
    #[inline(always)]
    fn wide_block(&self, index: u32) -> MemRead<'_, TriangleBlock> {
        match self.blocks.get(index as usize) {
            Some(b) => MemRead::InPlace(b),
            None => MemRead::Copied(INERT_BLOCK),
        }
    }
}
