use super::{PerfectHashLookup, RegisterState};
use crate::bvh2::{BvhMemory, NodeRef};
use crate::hash::lookup;
use crate::intersect::{RayContext, TriangleTest};
use crate::key::{self, Key};
use crate::observe::Observer;
use crate::traverse::{Machine, QueryState, Step};

/// A paused traversal (Sec. 2.4): the key of the next node and the bit trail. The register need
/// not be saved, because the backtracking step is made before pausing; the address comes back
/// from a hash over every node ([`HashCoverage::All`](crate::hash::HashCoverage)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Paused<K: Key> {
    /// Key of the next node to process.
    pub key: K,
    /// Bit trail relative to that node.
    pub trail: K,
}

impl<K: Key> Paused<K> {
    /// Pauses a traversal between steps.
    pub fn of<F: super::Fallback, const D: bool>(state: &RegisterState<K, F, D>) -> Self {
        let (key, trail) = state.key_and_trail();
        Self { key, trail }
    }

    /// Resumes after the ray's origin or direction changed: the old trail no longer says which
    /// uncles the ray misses, so every uncle up to the root is marked for a visit.
    pub fn after_ray_change(key: K) -> Self {
        Self { key, trail: ones_below(key::depth(key)) }
    }

    /// Resumes: looks the node address up from its key alone.
    pub fn resume<M: BvhMemory + ?Sized>(self, mem: &M) -> RegisterState<K, PerfectHashLookup, false> {
        let (addr, _) = lookup(mem, mem.hash_shape(), self.key);
        RegisterState::resume_at(addr, self.key, self.trail)
    }
}

/// `2^n - 1` for a generic key.
fn ones_below<K: Key>(n: u32) -> K {
    (0..n).fold(K::ZERO, |acc, _| acc.shl(1) ^ K::ONE)
}

/// Method (f): method (d), paused after every leaf that accepts a hit (as a renderer would, to
/// run an any-hit shader or to reorder rays) and resumed from the saved key and trail alone, within
/// the same step. Needs the hash over every node. Visits exactly the nodes method (d) visits.
#[derive(Clone, Copy, Debug)]
pub struct PausingState<K: Key>(RegisterState<K, PerfectHashLookup, false>);

impl<K: Key> PausingState<K> {
    /// Starts at `root`.
    #[inline(always)]
    pub fn new(root: NodeRef) -> Self {
        Self(RegisterState::new(root))
    }
}

impl<M: BvhMemory + ?Sized, T: TriangleTest, K: Key> Machine<M, RayContext<T>> for PausingState<K> {
    /// One step of method (d); after one that accepted a hit ([`Step::AfterHit`]), the pause and
    /// the resume through the hash.
    #[inline(always)]
    fn step<O: Observer>(&mut self, mem: &M, ctx: &RayContext<T>, q: &mut QueryState, obs: &mut O) -> Step {
        let step = self.0.step(mem, ctx, q, obs);
        if step == Step::AfterHit {
            self.0 = Paused::of(&self.0).resume(mem);
        }
        step
    }
}
