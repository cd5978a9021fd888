use crate::intersect::{BoxConstants, RayContext, SlabRay, TriangleTest};
use crate::method::Query;
use crate::traverse::QueryState;
use crate::{Hit, Ray};

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

/// Sets up each ray ([`begin`]), lets `trace` answer it and stores the answer; a ray that
/// [`begin`] turns away is a miss. Pairs rays and hits up to the shorter of the two.
#[inline(always)]
pub fn for_each_ray<T: TriangleTest, B: BoxConstants>(
    rays: &[Ray],
    hits: &mut [Hit],
    scene_scale: f32,
    query: Query,
    mut trace: impl FnMut(&RayContext<T, B>, &mut QueryState),
) {
    for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
        *hit = match begin::<T, B>(ray, scene_scale, query) {
            Some((ctx, mut q)) => {
                trace(&ctx, &mut q);
                q.hit()
            }
            None => Hit::MISS,
        };
    }
}
