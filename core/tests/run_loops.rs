//! The one-loop overrides of [`Machine::run`] (the wide stack and trail walks, the kd stack: what
//! the CPU backend traces with) against the same states driven step by step by [`drive`] (what the
//! default `run` and the simulator do): the same answer and the same events, ray for ray, also
//! when the step budget cuts a ray short.

use raytrail_core::bvh2::NodeRef;
use raytrail_core::hash::PerfectHash;
use raytrail_core::intersect::{KdRayContext, NoPair, Watertight};
use raytrail_core::kd::traverse::{scene_interval, KdRoot, KdStackState};
use raytrail_core::kd::{KdBuilder, KdSliceMemory};
use raytrail_core::method::{Collapse, Query};
use raytrail_core::observe::{Backtrack, Counters, Observer};
use raytrail_core::traverse::{begin, drive, Machine, QueryState};
use raytrail_core::wide::keyed::{keyed_nodes, WideHashedMemory};
use raytrail_core::wide::trail::WideTrailState;
use raytrail_core::wide::traverse::WideState;
use raytrail_core::wide::{FastKernel, ReferenceKernel, WideBvh};
use raytrail_core::Ray;

mod common;
use common::{soup, wide_soup, Rng};

/// Every event, in order.
#[derive(Debug, Default, PartialEq)]
struct Events {
    counters: Counters,
    log: Vec<(u8, u32, u32)>,
}

impl Observer for Events {
    fn node(&mut self, n: NodeRef) {
        self.counters.node(n);
        self.log.push((0, n.0, 0));
    }
    fn primitive(&mut self, p: u32) {
        self.counters.primitive(p);
        self.log.push((1, p, 0));
    }
    fn hit(&mut self, p: u32, t: f32) {
        self.counters.hit(p, t);
        self.log.push((2, p, t.to_bits()));
    }
    fn backtrack(&mut self, levels: u32, via: Backtrack) {
        self.counters.backtrack(levels, via);
        self.log.push((3, levels, 0));
    }
}

/// Rays from around and inside the soup in every direction, some axis-parallel.
fn rays(n: usize, seed: u64) -> Vec<Ray> {
    let mut r = Rng(seed);
    (0..n)
        .map(|i| {
            let o = r.v() * 14.0 - 2.0;
            let mut d = r.v() - 0.5;
            if i % 7 == 0 {
                d = glam::Vec3::new(0.0, d.y, 0.0);
            }
            Ray::new(o, d, 0.0, if i % 3 == 0 { 5.0 } else { f32::INFINITY })
        })
        .collect()
}

/// Traces `ray` with `fresh()` once through its [`Machine::run`] and once through [`drive`] (the
/// one step loop), and checks the same answer and the same events. Returns the nodes visited.
fn run_equals_drive<Mem: ?Sized, Ctx, S: Machine<Mem, Ctx>>(
    fresh: impl Fn() -> S,
    mem: &Mem,
    ctx: &Ctx,
    q0: QueryState,
    max_steps: u32,
    what: &dyn core::fmt::Debug,
) -> u64 {
    let (mut q_step, mut q_run) = (q0, q0);
    let (mut e_step, mut e_run) = (Events::default(), Events::default());
    drive(&mut fresh(), mem, ctx, &mut q_step, &mut e_step, max_steps);
    fresh().run(mem, ctx, &mut q_run, &mut e_run, max_steps);
    let bits = |h: raytrail_core::Hit| (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits());
    assert_eq!(bits(q_run.hit()), bits(q_step.hit()), "{what:?}");
    assert_eq!(e_run, e_step, "{what:?}");
    e_run.counters.internal_nodes + e_run.counters.leaves
}

fn compare<const W: usize, K: raytrail_core::wide::ChildKernel>(wide: &WideBvh<W>, scale: f32, max_steps: u32) -> u64 {
    let mem = wide.memory();
    let root = wide.root();
    let mut visited = 0;
    for (i, ray) in rays(1500, 11 + W as u64).iter().enumerate() {
        let query = if i % 2 == 0 { Query::Closest } else { Query::Any };
        let Some((ctx, q0)) = begin::<Watertight, NoPair>(ray, scale, query) else { continue };
        visited += run_equals_drive(|| WideState::<W, K>::new(root), &mem, &ctx, q0, max_steps, &(i, ray));
    }
    visited
}

/// [`compare`] for the stackless wide walk over the tree's perfect hash.
fn compare_trail<const W: usize>(wide: &WideBvh<W>, scale: f32, max_steps: u32) -> u64 {
    let (entries, _) = keyed_nodes(wide).unwrap();
    let (tables, _) = PerfectHash::build(&entries, wide.nodes().len()).unwrap();
    let mem = WideHashedMemory {
        tree: wide.memory(),
        displacement: &tables.displacement,
        cells: &tables.cells,
        shape: tables.shape,
    };
    let root = wide.root();
    let mut visited = 0;
    for (i, ray) in rays(1500, 31 + W as u64).iter().enumerate() {
        let query = if i % 2 == 0 { Query::Closest } else { Query::Any };
        let Some((ctx, q0)) = begin::<Watertight, NoPair>(ray, scale, query) else { continue };
        let fresh = || WideTrailState::<W, u64, FastKernel>::new(root);
        visited += run_equals_drive(fresh, &mem, &ctx, q0, max_steps, &(i, ray));
    }
    visited
}

#[test]
fn run_equals_stepping_the_state_machine() {
    let (scale, w4, w8) = wide_soup(4000, 5, Collapse::PullUp);
    for max_steps in [u32::MAX, 0, 1, 3, 10] {
        let visited = compare::<4, FastKernel>(&w4, scale, max_steps)
            + compare::<8, FastKernel>(&w8, scale, max_steps)
            + compare::<8, ReferenceKernel>(&w8, scale, max_steps);
        // The rays do reach into the tree (a budget of 0 still visits each root).
        assert!(visited > 3 * 1000, "budget {max_steps}: only {visited} nodes visited");
    }
}

#[test]
fn trail_run_equals_stepping_the_state_machine() {
    let (scale, w4, w8) = wide_soup(4000, 7, Collapse::PullUp);
    for max_steps in [u32::MAX, 0, 1, 3, 10] {
        let visited = compare_trail(&w4, scale, max_steps) + compare_trail(&w8, scale, max_steps);
        assert!(visited > 2 * 1000, "budget {max_steps}: only {visited} nodes visited");
    }
}

#[test]
fn kd_stack_run_equals_stepping_the_state_machine() {
    let tris = soup(3000, 9, 1.5);
    let tree = KdBuilder::default().build(&tris).unwrap();
    let mem = KdSliceMemory { nodes: tree.nodes(), prims: tree.prims(), triangles: &tris };
    let b = tree.bounds();
    let scale = b.min.abs().max(b.max.abs()).max_element();
    let root = KdRoot { lo: b.min, hi: b.max, scene_scale: scale, max_steps: u32::MAX, short_stack: 3 };
    for max_steps in [u32::MAX, 0, 1, 3, 10] {
        let mut visited = 0;
        for (i, ray) in rays(1500, 23).iter().enumerate() {
            let query = if i % 2 == 0 { Query::Closest } else { Query::Any };
            let Some((ctx, q0)) = begin::<Watertight, NoPair>(ray, scale, query) else { continue };
            let ctx: KdRayContext<Watertight> = ctx;
            let Some((t0, t1)) = scene_interval(&ctx, &root) else { continue };
            visited += run_equals_drive(|| KdStackState::new(t0, t1), &mem, &ctx, q0, max_steps, &(i, ray));
        }
        // The rays do reach into the tree (a budget of 0 still visits each ray's first node).
        assert!(visited > 500, "budget {max_steps}: only {visited} nodes visited");
    }
}
