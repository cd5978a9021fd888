//! BVH2 lanes: the core's BVH2 state machines ([`Machine`]) over a [`CountingMemory`].

use crate::memory::{CountingMemory, Traffic};
use crate::sim::{drive, LaneObserver, MethodRun, SimConfig};
use crate::start::Start;
use crate::stepper::{Outcome, Stepper};
use raytrail_core::bvh2::traverse::{
    order_children, Descent, ParentSiblingState, PausingState, PerfectHashLookup, RegisterState, StackState, TraceRoot,
    UncleHops,
};
use raytrail_core::bvh2::BvhMemory;
use raytrail_core::intersect::{RayContext, Watertight};
use raytrail_core::key::{Key, KeyWidth};
use raytrail_core::method::Bvh2Method;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::traverse::{Machine, QueryState, Step};
use raytrail_core::{Error, Ray};
use std::marker::PhantomData;

/// Simulates a BVH2 method with the key width the tree needs.
pub(crate) fn simulate_bvh2(
    prepared: &PreparedScene,
    m: Bvh2Method,
    rays: &[Ray],
    cfg: &SimConfig,
) -> Result<MethodRun, Error> {
    match prepared.key_width() {
        KeyWidth::W32 => keyed::<u32>(prepared, m, rays, cfg),
        KeyWidth::W64 => keyed::<u64>(prepared, m, rays, cfg),
    }
}

fn keyed<K: Key>(prepared: &PreparedScene, m: Bvh2Method, rays: &[Ray], cfg: &SimConfig) -> Result<MethodRun, Error> {
    let mem = CountingMemory::new(prepared.memory(m)?);
    let root = prepared.root(m)?;
    Ok(match m {
        Bvh2Method::Stack => drive(&Bvh2Lanes::<_, StackState<false>>::new(&mem, root, m), rays, cfg),
        Bvh2Method::StackDisjoint => drive(&Bvh2Lanes::<_, StackState<true>>::new(&mem, root, m), rays, cfg),
        Bvh2Method::ParentSibling => drive(&Bvh2Lanes::<_, ParentSiblingState<K>>::new(&mem, root, m), rays, cfg),
        Bvh2Method::Uncle => drive(&Bvh2Lanes::<_, RegisterState<K, UncleHops, false>>::new(&mem, root, m), rays, cfg),
        Bvh2Method::Hash => {
            drive(&Bvh2Lanes::<_, RegisterState<K, PerfectHashLookup, false>>::new(&mem, root, m), rays, cfg)
        }
        Bvh2Method::HashDisjoint => {
            drive(&Bvh2Lanes::<_, RegisterState<K, PerfectHashLookup, true>>::new(&mem, root, m), rays, cfg)
        }
        Bvh2Method::HashResume => drive(&Bvh2Lanes::<_, PausingState<K>>::new(&mem, root, m), rays, cfg),
    })
}

/// Lanes of one BVH2 method `S`.
struct Bvh2Lanes<'a, M: BvhMemory, S> {
    mem: &'a CountingMemory<M>,
    root: TraceRoot,
    /// Whether the method keeps a stack (else a postponed node goes to the register).
    stack: bool,
    /// Whether the method pauses after each accepted hit and resumes through the hash (f).
    resumes: bool,
    machine: PhantomData<S>,
}

impl<'a, M: BvhMemory, S> Bvh2Lanes<'a, M, S> {
    fn new(mem: &'a CountingMemory<M>, root: TraceRoot, method: Bvh2Method) -> Self {
        let stack = matches!(method, Bvh2Method::Stack | Bvh2Method::StackDisjoint);
        let resumes = method == Bvh2Method::HashResume;
        Self { mem, root, stack, resumes, machine: PhantomData }
    }
}

impl<M: BvhMemory, S: Start + Machine<CountingMemory<M>, RayContext<Watertight>>> Stepper for Bvh2Lanes<'_, M, S> {
    type Lane = (S, RayContext<Watertight>);

    fn begin(&self, ray: &Ray) -> Option<Self::Lane> {
        // As `trace_ray`: a ray that cannot hit anything, or whose distances overflow, visits
        // nothing.
        let ctx = RayContext::new(ray, self.root.scene_scale);
        (ray.is_traceable() && ctx.is_reliable()).then(|| (S::start(self.root.node), ctx))
    }

    fn step(&self, (state, ctx): &mut Self::Lane, q: &mut QueryState, obs: &mut LaneObserver) -> Outcome {
        // The culling distance before the step: an internal node's step uses it unchanged.
        let limit = q.limit();
        let hash_reads = self.mem.hash_reads();
        let step = state.step(self.mem, ctx, q, obs);
        // Only method (f) pauses and resumes, within each step that accepts a hit.
        let resumed = self.resumes && step == Step::AfterHit;
        let ev = obs.step;
        // Lanes step one after another, so the counter's growth is this lane's.
        let rounds = 1 + ev.link_reads + (self.mem.hash_reads() - hash_reads) as u32;
        // Re-derive (without counting the read) whether both children were hit: the stack
        // methods push then, the others fill the register.
        let postponed = ev.node.filter(|n| !n.is_leaf()).is_some_and(|n| {
            matches!(order_children(&self.mem.inner().node(n.index()), ctx, limit), Descent::Both { .. })
        }) as u32;
        let pushed = if self.stack { postponed } else { 0 };
        Outcome { step, resumed, postponed, pushed, dropped: 0, rounds }
    }

    fn max_steps(&self) -> u32 {
        self.root.max_steps
    }

    fn stack_entry_bytes(&self) -> u64 {
        if self.stack {
            4
        } else {
            0
        }
    }

    fn end_cycle(&self) -> u64 {
        self.mem.end_cycle()
    }

    fn traffic(&self) -> Traffic {
        self.mem.traffic()
    }
}
