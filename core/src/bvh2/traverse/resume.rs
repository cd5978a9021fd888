use super::TraceRoot;
use super::{PerfectHashLookup, RegisterState};
use crate::bvh2::BvhMemory;
use crate::hash::lookup;
use crate::intersect::{RayContext, TriangleTest};
use crate::key::{self, Key};
use crate::observe::Observer;
use crate::traverse::{QueryState, Step};

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
/// run an any-hit shader or to reorder rays) and resumed from the saved key and trail alone.
/// Needs the hash over every node. Visits exactly the nodes method (d) visits.
#[inline]
pub fn trace_pausing<K: Key, M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
    mem: &M,
    root: TraceRoot,
    ctx: &RayContext<T>,
    q: &mut QueryState,
    obs: &mut O,
) {
    let mut state = RegisterState::<K, PerfectHashLookup, false>::new(root.node);
    for _ in 0..=root.max_steps {
        match state.step(mem, ctx, q, obs) {
            Step::Continue => {}
            Step::Done => return,
            Step::AfterHit => state = Paused::of(&state).resume(mem),
        }
    }
}
