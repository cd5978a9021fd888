//! One interface over the core's per-method BVH2 state machines, so a BVH2 lane can be stepped
//! whatever its method.

use raytrail_core::bvh2::traverse::{
    ParentSiblingState, Paused, PerfectHashLookup, RegisterState, StackState, UncleHops,
};
use raytrail_core::bvh2::{BvhMemory, NodeRef};
use raytrail_core::intersect::{RayContext, TriangleTest};
use raytrail_core::key::Key;
use raytrail_core::observe::Observer;
use raytrail_core::traverse::{QueryState, Step};

/// A per-ray traversal state that makes one transition per [`Machine::step`].
pub trait Machine: Sized {
    /// A traversal starting at `root`.
    fn start(root: NodeRef) -> Self;

    /// One transition. Returns the step's outcome and whether the traversal paused and resumed
    /// during it (only [`Resuming`] does).
    fn step<M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
        &mut self,
        mem: &M,
        ctx: &RayContext<T>,
        q: &mut QueryState,
        obs: &mut O,
    ) -> (Step, bool);
}

/// Implements [`Machine`] for a core state type by forwarding to its own `step`.
macro_rules! forward {
    (impl $(<$($g:ident: $b:path),*>)? for $t:ty) => {
        impl$(<$($g: $b),*>)? Machine for $t {
            #[inline(always)]
            fn start(root: NodeRef) -> Self {
                <$t>::new(root)
            }
            #[inline(always)]
            fn step<M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
                &mut self,
                mem: &M,
                ctx: &RayContext<T>,
                q: &mut QueryState,
                obs: &mut O,
            ) -> (Step, bool) {
                (<$t>::step(self, mem, ctx, q, obs), false)
            }
        }
    };
}

forward!(impl for StackState<false>);
forward!(impl for StackState<true>);
forward!(impl<K: Key> for ParentSiblingState<K>);
forward!(impl<K: Key> for RegisterState<K, UncleHops, false>);
forward!(impl<K: Key> for RegisterState<K, PerfectHashLookup, false>);
forward!(impl<K: Key> for RegisterState<K, PerfectHashLookup, true>);

/// Method (f) as a lane: method (d) that, after each leaf accepting a hit, saves only key and
/// trail ([`Paused`]) and resumes through the hash over every node, within the same step (as
/// [`trace_pausing`](raytrail_core::bvh2::traverse::trace_pausing) does). The resume's lookup is read
/// through the lane's memory, so it is counted as hash traffic.
#[derive(Clone, Copy, Debug)]
pub struct Resuming<K: Key>(RegisterState<K, PerfectHashLookup, false>);

impl<K: Key> Machine for Resuming<K> {
    #[inline(always)]
    fn start(root: NodeRef) -> Self {
        Self(RegisterState::new(root))
    }
    #[inline(always)]
    fn step<M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
        &mut self,
        mem: &M,
        ctx: &RayContext<T>,
        q: &mut QueryState,
        obs: &mut O,
    ) -> (Step, bool) {
        let s = self.0.step(mem, ctx, q, obs);
        if s == Step::AfterHit {
            self.0 = Paused::of(&self.0).resume(mem);
            return (s, true);
        }
        (s, false)
    }
}
