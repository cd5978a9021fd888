use super::{trace_kd_packet, KdRestartState, KdStackState, RestartPolicy};
use crate::intersect::{KdRayContext, SlabRay, TriangleTest};
use crate::kd::KdMemory;
use crate::method::{KdMethod, Query};
use crate::observe::Observer;
use crate::traverse::{begin_slab, Machine, QueryState};
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
    /// [`TraceRoot`](crate::bvh2::traverse::TraceRoot)).
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

/// Traces one ray with `method`. The packet method traces it as a packet of one ray (the same
/// hits and leaves; batches of rays go through [`super::trace_kd_packet`] in packets of an octant).
#[inline]
pub fn trace_kd_ray<M: KdMemory + ?Sized, T: TriangleTest, O: Observer>(
    method: KdMethod,
    mem: &M,
    root: &KdRoot,
    ray: &Ray,
    query: Query,
    obs: &mut O,
) -> Hit {
    if method == KdMethod::Packet {
        let mut hit = [Hit::MISS];
        let policy = RestartPolicy::short_stack(root.short_stack);
        trace_kd_packet::<1, M, T, O>(
            mem,
            root,
            core::slice::from_ref(ray),
            query,
            policy,
            &mut hit,
            core::slice::from_mut(obs),
        );
        return hit[0];
    }
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
    let mut q = QueryState::new(ray, query);
    match method {
        KdMethod::Stack => KdStackState::new(t0, t1).run(mem, &ctx, &mut q, obs, root.max_steps),
        KdMethod::Restart => {
            KdRestartState::new(t0, t1, RestartPolicy::RESTART).run(mem, &ctx, &mut q, obs, root.max_steps)
        }
        KdMethod::PushDown => {
            KdRestartState::new(t0, t1, RestartPolicy::PUSH_DOWN).run(mem, &ctx, &mut q, obs, root.max_steps)
        }
        // The packet method went its own way above.
        KdMethod::ShortStack | KdMethod::Packet => KdRestartState::new(
            t0,
            t1,
            RestartPolicy::short_stack(root.short_stack),
        )
        .run(mem, &ctx, &mut q, obs, root.max_steps),
    }
    q.hit()
}
