//! kd lanes: the core's kd state machines ([`KdStackState`], [`KdRestartState`]) over a
//! [`CountingKdMemory`].
//!
//! The kd states keep their segment and stack private, and the observer reports pops and
//! restarts but not pushes. So each lane carries a model of the segment and stack, advanced with
//! the core's own [`cross`] at every inner node the machine visited and by the machine's pop and
//! restart events; it predicts the node the machine visits next, and every disagreement is
//! counted ([`MethodReport::stack_model_mismatches`](crate::MethodReport), required to be 0 by
//! the tests). The model only counts: the machine alone decides where the lane goes.

use crate::memory::{CountingKdMemory, Table, Traffic};
use crate::sim::{drive, LaneObserver, MethodRun, SimConfig};
use crate::stepper::{Outcome, Stepper};
use raytrail_core::intersect::{KdRayContext, Watertight};
use raytrail_core::kd::traverse::{
    cross, scene_interval, Crossing, KdRestartState, KdRoot, KdStackState, RestartPolicy,
};
use raytrail_core::kd::{KdMemory, KdSliceMemory};
use raytrail_core::method::KdMethod;
use raytrail_core::observe::Backtrack;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::traverse::{begin_slab, Machine, QueryState, Step};
use raytrail_core::{Error, Ray};
use std::cell::Cell;

/// Entries of the core's full kd stack (`KdStackState`: enough for a tree of depth 64).
const FULL_STACK: usize = 64;
/// A kd stack entry: node reference and the segment `[t_min, t_max]` it is entered over.
const KD_ENTRY_BYTES: u64 = 12;

/// Simulates a kd method; kd-packet is not a per-ray state machine and is refused.
pub(crate) fn simulate_kd(
    prepared: &PreparedScene,
    m: KdMethod,
    rays: &[Ray],
    cfg: &SimConfig,
) -> Result<MethodRun, Error> {
    if m == KdMethod::Packet {
        return Err(Error::Unsupported {
            method: m.name(),
            by: "the lockstep simulator (a packet of four rays is a lockstep unit itself)",
        });
    }
    let mem = CountingKdMemory::new(prepared.kd_memory()?);
    let lanes = KdLanes { mem: &mem, root: prepared.kd_root()?, method: m, mismatches: Cell::new(0) };
    let mut run = drive(&lanes, rays, cfg);
    run.report.stack_model_mismatches = lanes.mismatches.get();
    Ok(run)
}

/// The core's state for one of the four per-ray kd methods. Unboxed: a warp's lanes sit in one
/// vector and are stepped in place, and a warp holds one method's lanes only.
#[derive(Clone, Copy, Debug)]
#[allow(clippy::large_enum_variant)]
enum KdState {
    Stack(KdStackState),
    Restart(KdRestartState),
}

/// The lane's model of the machine's segment and stack (see the module docs).
#[derive(Clone, Debug)]
struct StackModel {
    t_min: f32,
    t_max: f32,
    scene_max: f32,
    /// Entries `(node, t_min, t_max)`, bottom first.
    entries: Vec<(u32, f32, f32)>,
    /// The node the machine must visit next, where the model knows it.
    expect: Option<u32>,
}

/// A lane: the core's state, the ray's constants and the model.
struct KdLane {
    state: KdState,
    ctx: KdRayContext<Watertight>,
    model: StackModel,
}

/// Lanes of one kd method.
struct KdLanes<'a> {
    mem: &'a CountingKdMemory<KdSliceMemory<'a>>,
    root: KdRoot,
    method: KdMethod,
    mismatches: Cell<u64>,
}

impl KdLanes<'_> {
    /// Stack entries the method keeps: the full stack, the short stack, or none (restart,
    /// push-down).
    fn capacity(&self) -> usize {
        match self.method {
            KdMethod::Stack => FULL_STACK,
            KdMethod::ShortStack | KdMethod::Packet => self.root.short_stack,
            KdMethod::Restart | KdMethod::PushDown => 0,
        }
    }
}

impl Stepper for KdLanes<'_> {
    type Lane = KdLane;

    fn begin(&self, ray: &Ray) -> Option<KdLane> {
        // As `trace_kd_ray`: rays that are not traceable or miss the tree's box visit nothing.
        let slab = begin_slab(ray, self.root.scene_scale)?;
        let ctx = KdRayContext::<Watertight>::from_slab(ray, slab);
        let (t0, t1) = scene_interval(&ctx, &self.root)?;
        let state = match self.method {
            KdMethod::Stack => KdState::Stack(KdStackState::new(t0, t1)),
            KdMethod::Restart => KdState::Restart(KdRestartState::new(t0, t1, RestartPolicy::RESTART)),
            KdMethod::PushDown => KdState::Restart(KdRestartState::new(t0, t1, RestartPolicy::PUSH_DOWN)),
            KdMethod::ShortStack | KdMethod::Packet => {
                KdState::Restart(KdRestartState::new(t0, t1, RestartPolicy::short_stack(self.root.short_stack)))
            }
        };
        let model = StackModel { t_min: t0, t_max: t1, scene_max: t1, entries: Vec::new(), expect: Some(0) };
        Some(KdLane { state, ctx, model })
    }

    fn step(&self, lane: &mut KdLane, q: &mut QueryState, obs: &mut LaneObserver) -> Outcome {
        let tally = self.mem.tally();
        let chain = [Table::KdNodes, Table::PrimRefs, Table::Triangles];
        let before = chain.map(|t| tally.reads(t));
        let step = match &mut lane.state {
            KdState::Stack(s) => s.step(self.mem, &lane.ctx, q, obs),
            KdState::Restart(s) => s.step(self.mem, &lane.ctx, q, obs),
        };
        // A node, then its leaf's references, then their triangles: each read needs the one
        // before it.
        let rounds = chain.iter().zip(before).filter(|&(&t, b)| tally.reads(t) > b).count() as u32;
        let mut out = Outcome { step, resumed: false, postponed: 0, pushed: 0, dropped: 0, rounds };
        let Some(node) = obs.step.node else { return out };
        let m = &mut lane.model;
        let visited = if node.is_leaf() { node.offset() } else { node.index() };
        if m.expect.is_some_and(|e| e != visited) {
            self.mismatches.set(self.mismatches.get() + 1);
        }
        m.expect = None;
        if !node.is_leaf() {
            let n = self.mem.inner().kd_node(visited);
            match cross(&n, &lane.ctx.slab, m.t_min, m.t_max) {
                Crossing::First(c) | Crossing::Second(c) => m.expect = Some(c),
                Crossing::Both { first, second, t_split } => {
                    out.postponed = 1;
                    let capacity = self.capacity();
                    if self.method == KdMethod::Stack && m.entries.len() < capacity {
                        m.entries.push((second, t_split, m.t_max));
                        out.pushed = 1;
                    } else if self.method != KdMethod::Stack && capacity > 0 {
                        // A full short stack loses its bottom entry; a restart finds it again.
                        if m.entries.len() == capacity {
                            m.entries.remove(0);
                            out.dropped = 1;
                        }
                        m.entries.push((second, t_split, m.t_max));
                        out.pushed = 1;
                    }
                    m.t_max = t_split;
                    m.expect = Some(first);
                }
            }
            return out;
        }
        match obs.step.backtrack {
            Some(Backtrack::StackPop) => match m.entries.pop() {
                Some((n, t0, t1)) => (m.expect, m.t_min, m.t_max) = (Some(n), t0, t1),
                None => self.mismatches.set(self.mismatches.get() + 1),
            },
            Some(Backtrack::Restart) => {
                // Back to the root or the pushed-down node (which the model does not track).
                (m.t_min, m.t_max) = (m.t_max, m.scene_max);
            }
            _ => {
                if step != Step::Done {
                    self.mismatches.set(self.mismatches.get() + 1);
                }
            }
        }
        out
    }

    fn max_steps(&self) -> u32 {
        self.root.max_steps
    }

    fn stack_entry_bytes(&self) -> u64 {
        if self.capacity() > 0 {
            KD_ENTRY_BYTES
        } else {
            0
        }
    }

    fn end_cycle(&self) -> u64 {
        self.mem.tally().end_cycle()
    }

    fn traffic(&self) -> Traffic {
        self.mem.tally().traffic()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::StepEvents;
    use raytrail_conformance::rays::primary;
    use raytrail_conformance::scenes::sphereflake;
    use raytrail_core::bvh2::SahBuilder;
    use raytrail_core::method::Query;

    #[test]
    fn a_model_that_loses_the_segment_is_caught() {
        // The tests require zero mismatches; this shows a wrong model does not pass unnoticed.
        let scene = sphereflake(1);
        let bvh = SahBuilder::default().build(scene.triangles()).unwrap();
        let prepared = PreparedScene::new(&scene, bvh, &[KdMethod::Stack.into()]).unwrap();
        let mem = CountingKdMemory::new(prepared.kd_memory().unwrap());
        let root = prepared.kd_root().unwrap();
        let lanes = KdLanes { mem: &mem, root, method: KdMethod::Stack, mismatches: Cell::new(0) };
        for ray in &primary(&scene, 16, 12) {
            let Some(mut lane) = lanes.begin(ray) else { continue };
            // An empty segment: the model sees every crossing as one child and pushes nothing,
            // so the machine's first pop finds the model's stack empty.
            lane.model.t_max = lane.model.t_min;
            let (mut q, mut obs) = (QueryState::new(ray, Query::Closest), LaneObserver::default());
            for _ in 0..=lanes.max_steps() {
                obs.step = StepEvents::default();
                if lanes.step(&mut lane, &mut q, &mut obs).step == Step::Done {
                    break;
                }
            }
        }
        assert!(lanes.mismatches.get() > 0);
    }
}
