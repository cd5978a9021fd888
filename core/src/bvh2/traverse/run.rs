use super::{ParentSiblingState, PausingState, PerfectHashLookup, RegisterState, StackState, UncleHops};
use crate::bvh2::{BvhMemory, NodeRef};
use crate::intersect::{SlabPair, TriangleTest};
use crate::key::Key;
use crate::method::{Bvh2Method, Query};
use crate::observe::Observer;
use crate::traverse::{for_each_ray, Machine};
use crate::{Hit, Ray};

/// Where a traversal starts, with the scene constant every ray needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceRoot {
    /// The root node.
    pub node: NodeRef,
    /// The largest coordinate magnitude in the scene (for [`RayContext::new`](crate::intersect::RayContext::new)).
    pub scene_scale: f32,
    /// Steps after which traversal stops: the node count, since no method visits a node twice.
    /// It never binds on intact tables; on damaged ones it guarantees termination.
    pub max_steps: u32,
}

/// Traces one ray with `method` over `mem` (which must hold what the method needs: the
/// parent/sibling layout for [`Bvh2Method::ParentSibling`], the uncle layout otherwise, and the hash
/// tables for the hash methods). `K` is the key and trail type the tree's depth needs.
///
/// A ray that is not traceable ([`Ray::is_traceable`]) is a miss and visits nothing.
#[inline]
pub fn trace_ray<K: Key, M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
    method: Bvh2Method,
    mem: &M,
    root: TraceRoot,
    ray: &Ray,
    query: Query,
    obs: &mut O,
) -> Hit {
    let mut hit = Hit::MISS;
    trace_batch::<K, M, T, O>(
        method,
        mem,
        root,
        core::slice::from_ref(ray),
        core::slice::from_mut(&mut hit),
        query,
        obs,
    );
    hit
}

/// Traces `rays` into `hits` (pairs up to the shorter of the two), each exactly as [`trace_ray`]
/// would, with the method dispatched once per batch and a stack set up once per batch rather than
/// once per ray (the CPU backend's hot loop).
#[inline]
pub fn trace_batch<K: Key, M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
    method: Bvh2Method,
    mem: &M,
    root: TraceRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    obs: &mut O,
) {
    let r = root.node;
    match method {
        Bvh2Method::Stack => {
            let mut s = StackState::<false>::new(r);
            for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
                s.restart(r);
                s.run(mem, ctx, q, obs, root.max_steps);
            });
        }
        Bvh2Method::StackDisjoint => {
            let mut s = StackState::<true>::new(r);
            for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
                s.restart(r);
                s.run(mem, ctx, q, obs, root.max_steps);
            });
        }
        Bvh2Method::ParentSibling => for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
            ParentSiblingState::<K>::new(r).run(mem, ctx, q, obs, root.max_steps)
        }),
        Bvh2Method::Uncle => for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
            RegisterState::<K, UncleHops, false>::new(r).run(mem, ctx, q, obs, root.max_steps)
        }),
        Bvh2Method::Hash => for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
            RegisterState::<K, PerfectHashLookup, false>::new(r).run(mem, ctx, q, obs, root.max_steps)
        }),
        Bvh2Method::HashDisjoint => for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
            RegisterState::<K, PerfectHashLookup, true>::new(r).run(mem, ctx, q, obs, root.max_steps)
        }),
        Bvh2Method::HashResume => for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
            PausingState::<K>::new(r).run(mem, ctx, q, obs, root.max_steps)
        }),
    }
}
