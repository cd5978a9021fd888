//! Wide-BVH lanes: the core's [`WideState`] over a [`CountingWideMemory`], with the
//! [`FastKernel`] the CPU backend traces with.

use crate::memory::{CountingWideMemory, Traffic};
use crate::sim::{drive, LaneObserver, MethodRun, SimConfig};
use crate::stepper::{Outcome, Stepper};
use raytrail_core::intersect::{NoPair, Watertight};
use raytrail_core::method::{Query, WideMethod};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::traverse::{begin, Machine, QueryState};
use raytrail_core::wide::traverse::{WideRayContext, WideRoot, WideState};
use raytrail_core::wide::{ChildKernel, FastKernel, WideMemory, WideTree};
use raytrail_core::{Error, Ray};

/// A wide stack entry: child reference and the entry distance it was found at.
const WIDE_ENTRY_BYTES: u64 = 8;

/// Simulates a wide method over its tree, of its width.
pub(crate) fn simulate_wide(
    prepared: &PreparedScene,
    m: WideMethod,
    rays: &[Ray],
    cfg: &SimConfig,
) -> Result<MethodRun, Error> {
    let root = prepared.wide_root(m)?;
    Ok(match prepared.wide_tree(m)? {
        WideTree::Four(t) => drive(&WideLanes::<4, _>::new(t.memory(), root, cfg.query), rays, cfg),
        WideTree::Eight(t) => drive(&WideLanes::<8, _>::new(t.memory(), root, cfg.query), rays, cfg),
    })
}

/// The children the step's internal node hit (0 after a leaf), re-derived from `mem` without
/// counting the read, with the culling distance `limit` the step started from (an internal
/// node's step uses it unchanged).
pub(crate) fn hit_children<const W: usize, M: WideMemory<W>>(
    mem: &M,
    obs: &LaneObserver,
    ctx: &WideRayContext<Watertight>,
    limit: f32,
) -> u32 {
    obs.step.node.filter(|n| !n.is_leaf()).map_or(0, |n| {
        let node = mem.wide_node(n.index());
        let (lo, hi) = ctx.box_interval(limit);
        FastKernel::test::<W>(&node, &ctx.slab, lo, hi).mask.count_ones()
    })
}

/// Lanes of a `W`-wide tree.
struct WideLanes<const W: usize, M> {
    mem: CountingWideMemory<M>,
    root: WideRoot,
    query: Query,
}

impl<const W: usize, M: WideMemory<W>> WideLanes<W, M> {
    fn new(mem: M, root: WideRoot, query: Query) -> Self {
        Self { mem: CountingWideMemory::new(mem), root, query }
    }
}

impl<const W: usize, M: WideMemory<W>> Stepper for WideLanes<W, M> {
    type Lane = (WideState<W, FastKernel>, WideRayContext<Watertight>);

    fn begin(&self, ray: &Ray) -> Option<Self::Lane> {
        // As `trace_wide_batch`: a ray `begin` turns away visits nothing.
        let (ctx, _) = begin::<Watertight, NoPair>(ray, self.root.scene_scale, self.query)?;
        Some((WideState::new(self.root.root), ctx))
    }

    fn step(&self, (state, ctx): &mut Self::Lane, q: &mut QueryState, obs: &mut LaneObserver) -> Outcome {
        let limit = q.limit();
        let step = state.step(&self.mem, ctx, q, obs);
        // Every hit child but the one visited next is pushed.
        let pushed = hit_children::<W, _>(self.mem.inner(), obs, ctx, limit).saturating_sub(1);
        // A node's address comes from its parent, a leaf's triangles from the parent's slot, and
        // the primitive ids of a leaf's positions are known with the triangles: one round trip.
        Outcome { step, resumed: false, postponed: pushed, pushed, dropped: 0, rounds: 1 }
    }

    fn max_steps(&self) -> u32 {
        self.root.max_steps
    }

    fn stack_entry_bytes(&self) -> u64 {
        WIDE_ENTRY_BYTES
    }

    fn end_cycle(&self) -> u64 {
        self.mem.tally().end_cycle()
    }

    fn traffic(&self) -> Traffic {
        self.mem.tally().traffic()
    }
}
