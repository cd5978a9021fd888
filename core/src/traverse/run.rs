use super::{
    trace_pausing, Method, ParentSiblingState, PerfectHashLookup, Query, QueryState, RegisterState, StackState, Step,
    UncleHops,
};
use crate::bvh2::{BvhMemory, NodeRef};
use crate::intersect::{RayContext, TriangleTest};
use crate::key::Key;
use crate::observe::Observer;
use crate::{Hit, Ray};

/// Where a traversal starts, with the scene constant every ray needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceRoot {
    /// The root node.
    pub node: NodeRef,
    /// The largest coordinate magnitude in the scene (for [`RayContext::new`]).
    pub scene_scale: f32,
    /// Steps after which traversal stops: the node count, since no method visits a node twice.
    /// It never binds on intact tables; on damaged ones it guarantees termination.
    pub max_steps: u32,
}

/// The per-ray constants and an empty answer, or `None` for a ray every method treats as a miss
/// (not traceable, or with distances that overflow: [`RayContext::is_reliable`]).
#[inline(always)]
pub fn begin<T: TriangleTest>(ray: &Ray, scene_scale: f32, query: Query) -> Option<(RayContext<T>, QueryState)> {
    if !ray.is_traceable() {
        return None;
    }
    let ctx = RayContext::<T>::new(ray, scene_scale);
    ctx.is_reliable().then(|| (ctx, QueryState::new(ray, query == Query::Any)))
}

/// Traces one ray with `method` over `mem` (which must hold what the method needs: the
/// parent/sibling layout for [`Method::ParentSibling`], the uncle layout otherwise, and the hash
/// tables for the hash methods). `K` is the key and trail type the tree's depth needs.
///
/// A ray that is not traceable ([`Ray::is_traceable`]) is a miss and visits nothing.
#[inline]
pub fn trace_ray<K: Key, M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
    method: Method,
    mem: &M,
    root: TraceRoot,
    ray: &Ray,
    query: Query,
    obs: &mut O,
) -> Hit {
    let Some((ctx, mut q)) = begin::<T>(ray, root.scene_scale, query) else {
        return Hit::MISS;
    };
    let r = root.node;
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
        Method::Stack => drive!(StackState::<false>::new(r)),
        Method::StackDisjoint => drive!(StackState::<true>::new(r)),
        Method::ParentSibling => drive!(ParentSiblingState::<K>::new(r)),
        Method::Uncle => drive!(RegisterState::<K, UncleHops, false>::new(r)),
        Method::Hash => drive!(RegisterState::<K, PerfectHashLookup, false>::new(r)),
        Method::HashDisjoint => drive!(RegisterState::<K, PerfectHashLookup, true>::new(r)),
        Method::HashResume => trace_pausing::<K, M, T, O>(mem, root, &ctx, &mut q, obs),
        // kd-tree methods run through `kd::traverse`; given BVH2 memory they find nothing.
        _ => return Hit::MISS,
    }
    q.hit
}
