use crate::intersect::{BoxConstants, RayContext, SlabRay, TriangleTest};
use crate::method::Query;
use crate::traverse::QueryState;
use crate::Ray;

/// The per-ray constants and an empty answer, or `None` for a ray every method treats as a miss
/// (not traceable, or with distances that overflow: [`RayContext::is_reliable`]).
#[inline(always)]
pub fn begin<T: TriangleTest, B: BoxConstants>(
    ray: &Ray,
    scene_scale: f32,
    query: Query,
) -> Option<(RayContext<T, B>, QueryState)> {
    let slab = begin_slab(ray, scene_scale)?;
    Some((RayContext::from_slab(ray, slab), QueryState::new(ray, query)))
}

/// The first stage of [`begin`]: the slab constants with their slack, or `None` where `begin`
/// turns the ray away. A traversal that tests one box first (the kd-tree's scene box) makes the
/// rest of the context only for rays that enter it.
#[inline(always)]
pub fn begin_slab(ray: &Ray, scene_scale: f32) -> Option<SlabRay> {
    if !ray.is_traceable() {
        return None;
    }
    let slab = SlabRay::with_slack(ray, scene_scale);
    slab.slack.is_finite().then_some(slab)
}
