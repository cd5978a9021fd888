use super::{KdRestartState, KdStackState};
use crate::intersect::{KdRayContext, SlabRay, TriangleTest};
use crate::kd::KdMemory;
use crate::observe::Observer;
use crate::traverse::{begin_slab, Method, Query, QueryState, Step};
use crate::{Hit, Ray};
use glam::Vec3;

/// Where a kd traversal starts: the box the tree partitions, and the scene constants every ray
/// needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdRoot {
    /// Lower corner of the tree's box.
    pub lo: Vec3,
    /// Upper corner.
    pub hi: Vec3,
    /// Largest coordinate magnitude in the scene (for [`RayContext::new`](crate::intersect::RayContext::new)).
    pub scene_scale: f32,
    /// Steps after which traversal stops (it never binds on an intact tree; see
    /// [`TraceRoot`](crate::traverse::TraceRoot)).
    pub max_steps: u32,
    /// Entries of the short stack (Horn et al. use 3).
    pub short_stack: usize,
}

/// The ray's segment inside the tree's box, `[scene_min, scene_max]`, if it meets the box; the
/// ray's interval is widened by its slack as for BVH2 boxes (see
/// [`RayContext::box_interval`](crate::intersect::RayContext::box_interval)).
#[inline(always)]
pub fn scene_interval<T: TriangleTest>(ctx: &KdRayContext<T>, root: &KdRoot) -> Option<(f32, f32)> {
    scene_segment(&ctx.ray, &ctx.slab, root)
}

/// [`scene_interval`] from the ray and its slab constants alone.
#[inline(always)]
fn scene_segment(ray: &Ray, slab: &SlabRay, root: &KdRoot) -> Option<(f32, f32)> {
    let (lo, hi) = slab.widen(ray.tmin, ray.tmax);
    slab.hit(root.lo, root.hi, lo, hi).map(|h| (h.t_enter, h.t_exit))
}

/// Traces one ray with a single-ray kd method (stack, restart, push-down, short-stack).
/// Other methods return a miss; the packet method goes through [`super::trace_kd_packet`].
#[inline]
pub fn trace_kd_ray<M: KdMemory + ?Sized, T: TriangleTest, O: Observer>(
    method: Method,
    mem: &M,
    root: &KdRoot,
    ray: &Ray,
    query: Query,
    obs: &mut O,
) -> Hit {
    // The scene box is tested before the rest of the context is made: most secondary rays that
    // leave the scene do so here (97% of Sponza's ambient-occlusion rays), and for them the
    // context and query state were stores that the box test's loads then waited on.
    let Some(slab) = begin_slab(ray, root.scene_scale) else {
        return Hit::MISS;
    };
    let Some((t0, t1)) = scene_segment(ray, &slab, root) else {
        return Hit::MISS;
    };
    let ctx = KdRayContext::<T>::from_slab(ray, slab);
    let mut q = QueryState::new(ray, query == Query::Any);
    macro_rules! drive {
        ($state:expr) => {{
            let mut s = $state;
            let mut budget = root.max_steps;
            while s.step(mem, &ctx, &mut q, obs) != Step::Done && budget > 0 {
                budget -= 1;
            }
        }};
    }
    match method {
        Method::KdStack => drive!(KdStackState::new(t0, t1)),
        Method::KdRestart => drive!(KdRestartState::new(t0, t1, false, 0)),
        Method::KdPushDown => drive!(KdRestartState::new(t0, t1, true, 0)),
        Method::KdShortStack => drive!(KdRestartState::new(t0, t1, true, root.short_stack)),
        _ => return Hit::MISS,
    }
    q.hit
}
