//! The ray/box and ray/triangle tests every method shares.
//!
//! Per-ray constants (reciprocal direction, octant, shear) are computed once per ray by
//! [`RayContext::new`], in one place, so that every method and backend makes the same decisions.

mod block;
mod context;
mod moller_trumbore;
mod refine;
mod slab;
mod slab_pair;
#[cfg(test)]
pub(crate) mod test_values;
mod watertight;

pub use block::{BlockHits, TriangleBlock, BLOCK};
pub use context::{BoxConstants, KdRayContext, NoPair, RayContext, RELIABLE_LIMIT, SLACK_SCALE, SLACK_ULPS};
pub use moller_trumbore::MollerTrumbore;
pub use refine::{REFINE_SCALE, REFINE_ULPS};
pub use slab::{BoxHit, SlabRay, FAR_PAD};
pub use slab_pair::{hit_pair_scalar, SlabPair};
pub use watertight::{ShearedRay, Watertight, EDGE_STEP, TINY_EDGE};

use crate::Ray;
use glam::Vec3;

/// A ray/triangle hit before it is attributed to a primitive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter.
    pub t: f32,
    /// Barycentric weight of the second vertex.
    pub u: f32,
    /// Barycentric weight of the third vertex.
    pub v: f32,
}

/// A ray/triangle test, chosen at compile time so the hot loop is monomorphized.
pub trait TriangleTest: Copy + Default + Send + Sync + 'static {
    /// Per-ray constants, computed once per ray.
    type PerRay: Copy;
    /// Short name, as used on the command line.
    const NAME: &'static str;
    /// Computes the per-ray constants.
    fn prepare(ray: &Ray) -> Self::PerRay;
    /// Hit of the ray with triangle `(a, b, c)` for `t` in `[tmin, tmax]`, if any.
    fn intersect(ray: &Self::PerRay, a: Vec3, b: Vec3, c: Vec3, tmin: f32, tmax: f32) -> Option<TriangleHit>;
    /// [`TriangleTest::intersect`] with the vertices read where they are stored, so a test that
    /// picks coordinates by a per-ray index loads just those; the default copies the vertices.
    #[inline(always)]
    fn intersect_in_place(ray: &Self::PerRay, v: [&[f32; 3]; 3], tmin: f32, tmax: f32) -> Option<TriangleHit> {
        let [a, b, c] = v.map(|p| Vec3::from_array(*p));
        Self::intersect(ray, a, b, c, tmin, tmax)
    }
    /// The four triangles of `block` against one interval, each lane's answer what
    /// [`TriangleTest::intersect_in_place`] gives for it bit for bit; the default tests the lanes
    /// one by one, a test may do them at once.
    #[inline(always)]
    fn intersect_block(ray: &Self::PerRay, block: &TriangleBlock, tmin: f32, tmax: f32) -> BlockHits {
        let mut out = BlockHits::NONE;
        for lane in 0..BLOCK {
            let [a, b, c] = block.lane(lane);
            out.set(lane, Self::intersect_in_place(ray, [&a, &b, &c], tmin, tmax));
        }
        out
    }
    /// These per-ray constants as the watertight test's, where this test is that one (`None`
    /// otherwise): a backend's own vector form of the watertight test reads them, and must give
    /// [`TriangleTest::intersect_in_place`]'s answers bit for bit.
    #[inline(always)]
    fn sheared(_ray: &Self::PerRay) -> Option<&ShearedRay> {
        None
    }
}
