use super::KdNode;
use crate::bvh2::MemRead;
use crate::geometry::Triangle;
use glam::Vec3;

/// Every memory read a kd-tree traversal makes goes through this trait (see
/// [`BvhMemory`](crate::bvh2::BvhMemory) for why).
pub trait KdMemory {
    /// Node `index`.
    fn kd_node(&self, index: u32) -> KdNode;
    /// Entry `i` of the leaves' primitive-reference array.
    fn prim_ref(&self, i: u32) -> u32;
    /// The vertices of primitive `prim`.
    fn triangle(&self, prim: u32) -> [Vec3; 3];
    /// The vertices of primitive `prim` for reading: [`KdMemory::triangle`]'s copy unless the
    /// memory can lend them in place (as [`KdSliceMemory`] does).
    #[inline(always)]
    fn read_triangle(&self, prim: u32) -> MemRead<'_, [Vec3; 3]> {
        MemRead::Copied(self.triangle(prim))
    }
}

/// A kd-tree and the scene's triangles in plain slices: the CPU backend's memory.
#[derive(Clone, Copy, Debug)]
pub struct KdSliceMemory<'a> {
    /// Nodes.
    pub nodes: &'a [KdNode],
    /// Primitive references.
    pub prims: &'a [u32],
    /// Triangles by primitive id.
    pub triangles: &'a [Triangle],
}

impl KdMemory for KdSliceMemory<'_> {
    #[inline(always)]
    fn kd_node(&self, index: u32) -> KdNode {
        self.nodes[index as usize]
    }
    #[inline(always)]
    fn prim_ref(&self, i: u32) -> u32 {
        self.prims[i as usize]
    }
    #[inline(always)]
    fn triangle(&self, prim: u32) -> [Vec3; 3] {
        self.triangles[prim as usize].v
    }
    #[inline(always)]
    fn read_triangle(&self, prim: u32) -> MemRead<'_, [Vec3; 3]> {
        MemRead::InPlace(&self.triangles[prim as usize].v)
    }
}
