use super::leaf_block::LeafBlock;
use super::node::WideNode;
use crate::bvh2::MemRead;
use crate::geometry::Triangle;
use crate::intersect::{TriangleBlock, BLOCK};
use glam::Vec3;

/// Every memory read a wide-BVH traversal makes goes through this trait (see
/// [`BvhMemory`](crate::bvh2::BvhMemory) for why).
pub trait WideMemory<const W: usize> {
    /// Node `index`.
    fn wide_node(&self, index: u32) -> MemRead<'_, WideNode<W>>;
    /// The primitive id of the triangle at position `pos`.
    fn prim(&self, pos: u32) -> u32;
    /// The vertices of the triangle at position `pos`.
    fn wide_triangle(&self, pos: u32) -> MemRead<'_, [Vec3; 3]>;
    /// The block of four triangles `index` (positions `4 index ..`).
    fn wide_block(&self, index: u32) -> MemRead<'_, TriangleBlock>;
    /// Whether [`WideMemory::prefetch_child`] does anything. [`WideMemory::prefetch_hit_children`]
    /// skips its loop over the hit slots where it does not: the compiler keeps an empty loop over mask bits, whose
    /// exit branch depends on the number of children hit.
    const PREFETCHES: bool = false;
    /// A hint, right after `node`'s box test, that its hit child `slot` will be visited: memory
    /// that can bring it closer starts loading it. By default nothing happens.
    #[inline(always)]
    fn prefetch_child(&self, _node: &WideNode<W>, _slot: usize) {}
    /// [`WideMemory::prefetch_child`] for every slot of `mask` (a bit per hit child), or nothing
    /// at all, not even the loop over the bits, where the memory does not prefetch.
    #[inline(always)]
    fn prefetch_hit_children(&self, node: &WideNode<W>, mask: u32) {
        if Self::PREFETCHES {
            let mut m = mask;
            while m != 0 {
                self.prefetch_child(node, m.trailing_zeros() as usize);
                m &= m - 1;
            }
        }
    }
}

/// A wide tree in plain slices: the CPU backend's memory.
#[derive(Clone, Copy, Debug)]
pub struct WideSliceMemory<'a, const W: usize> {
    /// Nodes.
    pub nodes: &'a [WideNode<W>],
    /// Triangles in leaf order.
    pub triangles: &'a [Triangle],
    /// The same triangles in blocks of four, with their primitive ids.
    pub blocks: &'a [LeafBlock],
}

impl<const W: usize> WideMemory<W> for WideSliceMemory<'_, W> {
    #[inline(always)]
    fn wide_node(&self, index: u32) -> MemRead<'_, WideNode<W>> {
        MemRead::InPlace(&self.nodes[index as usize])
    }
    #[inline(always)]
    fn prim(&self, pos: u32) -> u32 {
        self.blocks[pos as usize / BLOCK].prims[pos as usize % BLOCK]
    }
    #[inline(always)]
    fn wide_triangle(&self, pos: u32) -> MemRead<'_, [Vec3; 3]> {
        MemRead::InPlace(&self.triangles[pos as usize].v)
    }
    #[inline(always)]
    fn wide_block(&self, index: u32) -> MemRead<'_, TriangleBlock> {
        MemRead::InPlace(&self.blocks[index as usize].triangles)
    }
}
