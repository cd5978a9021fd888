use super::{trace_pausing, Fallback, ParentSiblingState, PerfectHashLookup, RegisterState, StackState, UncleHops};
use crate::bvh2::{BvhMemory, NodeRef};
use crate::intersect::{RayContext, SlabPair, TriangleTest};
use crate::key::Key;
use crate::method::{Bvh2Method, Query};
use crate::observe::Observer;
use crate::traverse::{for_each_ray, QueryState, Step};
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
                drive(&mut s, mem, ctx, q, obs, root.max_steps);
            });
        }
        Bvh2Method::StackDisjoint => {
            let mut s = StackState::<true>::new(r);
            for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
                s.restart(r);
                drive(&mut s, mem, ctx, q, obs, root.max_steps);
            });
        }
        Bvh2Method::ParentSibling => for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
            drive(&mut ParentSiblingState::<K>::new(r), mem, ctx, q, obs, root.max_steps)
        }),
        Bvh2Method::Uncle => for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
            drive(&mut RegisterState::<K, UncleHops, false>::new(r), mem, ctx, q, obs, root.max_steps)
        }),
        Bvh2Method::Hash => for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
            drive(&mut RegisterState::<K, PerfectHashLookup, false>::new(r), mem, ctx, q, obs, root.max_steps)
        }),
        Bvh2Method::HashDisjoint => for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
            drive(&mut RegisterState::<K, PerfectHashLookup, true>::new(r), mem, ctx, q, obs, root.max_steps)
        }),
        Bvh2Method::HashResume => for_each_ray::<T, SlabPair>(rays, hits, root.scene_scale, query, |ctx, q| {
            trace_pausing::<K, M, T, O>(mem, root, ctx, q, obs)
        }),
    }
}

/// A BVH2 traversal state that makes one transition per [`Machine::step`].
trait Machine {
    /// One transition; see [`Step`].
    fn step<M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
        &mut self,
        mem: &M,
        ctx: &RayContext<T>,
        q: &mut QueryState,
        obs: &mut O,
    ) -> Step;
}

impl<const DISJOINT: bool> Machine for StackState<DISJOINT> {
    #[inline(always)]
    fn step<M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
        &mut self,
        mem: &M,
        ctx: &RayContext<T>,
        q: &mut QueryState,
        obs: &mut O,
    ) -> Step {
        StackState::step(self, mem, ctx, q, obs)
    }
}

impl<K: Key> Machine for ParentSiblingState<K> {
    #[inline(always)]
    fn step<M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
        &mut self,
        mem: &M,
        ctx: &RayContext<T>,
        q: &mut QueryState,
        obs: &mut O,
    ) -> Step {
        ParentSiblingState::step(self, mem, ctx, q, obs)
    }
}

impl<K: Key, F: Fallback, const DISJOINT: bool> Machine for RegisterState<K, F, DISJOINT> {
    #[inline(always)]
    fn step<M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
        &mut self,
        mem: &M,
        ctx: &RayContext<T>,
        q: &mut QueryState,
        obs: &mut O,
    ) -> Step {
        RegisterState::step(self, mem, ctx, q, obs)
    }
}

/// Steps `state` until it is done, or for at most `max_steps` further steps after the first
/// (see [`TraceRoot::max_steps`]).
#[inline(always)]
fn drive<S: Machine, M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
    state: &mut S,
    mem: &M,
    ctx: &RayContext<T>,
    q: &mut QueryState,
    obs: &mut O,
    max_steps: u32,
) {
    let mut budget = max_steps;
    while state.step(mem, ctx, q, obs) != Step::Done && budget > 0 {
        budget -= 1;
    }
}
