//! The lockstep driver: rays in warps of `W` lanes, every unfinished lane making one transition
//! per cycle, with what each transition was and what it read.

use crate::machine::{Machine, Resuming};
use crate::memory::{CountingMemory, Traffic};
use raytrail_core::bvh2::traverse::{
    order_children, Descent, ParentSiblingState, PerfectHashLookup, RegisterState, StackState, TraceRoot, UncleHops,
};
use raytrail_core::bvh2::{BvhMemory, NodeRef};
use raytrail_core::intersect::{RayContext, Watertight};
use raytrail_core::key::{Key, KeyWidth};
use raytrail_core::method::{Bvh2Method, Method, Query};
use raytrail_core::observe::{Backtrack, Counters, Observer};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::traverse::{QueryState, Step};
use raytrail_core::{Error, Hit, Ray};

/// How to simulate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SimConfig {
    /// Lanes per warp (rays stepped together); 0 is taken as 1.
    pub warp: usize,
    /// Closest or any hit.
    pub query: Query,
    /// Keep every ray's node enumeration (for checks; costs memory).
    pub record_enumerations: bool,
    /// Keep the cycle-by-cycle [`CycleRecord`]s of the warp that takes the most cycles.
    pub record_timeline: bool,
}

impl SimConfig {
    /// Warps of 32 lanes (a GPU warp), closest hit, recording nothing extra.
    pub fn new(query: Query) -> Self {
        Self { warp: 32, query, record_enumerations: false, record_timeline: false }
    }
}

/// What one lane did in one cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Transition {
    /// Not stepped: its traversal had ended.
    Idle,
    /// An internal node whose traversal went on down.
    Internal,
    /// A leaf after which traversal ended or went on without a backtracking step.
    Leaf,
    /// A node then a backtracking step, served as given.
    Backtrack {
        /// The node was a leaf (else an internal node whose child boxes were both missed).
        leaf: bool,
        /// What served the step.
        via: Backtrack,
    },
}

impl Transition {
    /// One character for timelines: `.` idle, `i` internal, `l` leaf; backtracks: `s` stack pop,
    /// `r` register, `h` hash, `w` walk over links (iterative), upper case after a leaf.
    pub fn symbol(self) -> char {
        match self {
            Transition::Idle => '.',
            Transition::Internal => 'i',
            Transition::Leaf => 'l',
            Transition::Backtrack { leaf, via } => {
                let c = match via {
                    Backtrack::StackPop => 's',
                    Backtrack::Register(_) => 'r',
                    Backtrack::Hash { .. } => 'h',
                    Backtrack::Iterative => 'w',
                    // Restarts belong to the kd methods, which the simulator does not step.
                    Backtrack::Restart => 'x',
                };
                if leaf {
                    c.to_ascii_uppercase()
                } else {
                    c
                }
            }
        }
    }
}

/// One cycle of one warp.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CycleRecord {
    /// Lanes stepped.
    pub active: u32,
    /// Dependent memory round trips of the slowest lane (see [`MethodReport::latency_cycles`]).
    pub rounds: u32,
    /// Distinct cache lines the cycle's reads touched.
    pub lines: u64,
    /// Each lane's transition.
    pub lanes: Vec<Transition>,
}

/// Transition counts by kind, summed over lane-steps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TransitionCounts {
    /// Steps that processed an internal node.
    pub internal: u64,
    /// Steps that processed a leaf.
    pub leaf: u64,
    /// Backtracking steps served by a stack pop.
    pub stack_pop: u64,
    /// ... by the most-recently-postponed-node register.
    pub register: u64,
    /// ... by the perfect hash.
    pub hash: u64,
    /// ... by walking parent or uncle links.
    pub iterative: u64,
}

/// What a method cost over a batch of rays in lockstep.
#[derive(Clone, Debug, PartialEq)]
pub struct MethodReport {
    /// The method.
    pub method: Method,
    /// Rays traced.
    pub rays: usize,
    /// Lanes per warp.
    pub warp: usize,
    /// Warps (the last one may be partly empty).
    pub warps: usize,
    /// Cycles over all warps (one transition per active lane per cycle).
    pub cycles: u64,
    /// Cycles if each dependent memory round trip of a step took a cycle and a warp-step waited
    /// for its slowest lane: a step fetches its node or leaf (1), then each link read of a walk
    /// and each hash read (displacement, cell) depends on the one before. A rough latency model
    /// that tells constant-time from iterative backtracking, which [`Self::cycles`] cannot.
    pub latency_cycles: u64,
    /// Lane-steps over all cycles (the sum of active lanes).
    pub lane_steps: u64,
    /// Cycles in which some lanes processed internal nodes and others leaves: the two are
    /// different code paths, so a SIMT machine would serialize them.
    pub divergent_cycles: u64,
    /// Transitions by kind.
    pub transitions: TransitionCounts,
    /// Nodes postponed (both children hit): stack pushes for the stack methods, register
    /// writes for the others.
    pub postponed: u64,
    /// Most stack entries live at once in any ray (pushes minus pops; for stack-disjoint an upper
    /// bound, since its hits drop entries without popping them). Zero for stackless methods.
    pub peak_stack: u32,
    /// Pauses and resumes (hash-resume only).
    pub resumes: u64,
    /// Memory traffic.
    pub traffic: Traffic,
    /// The core's work counters, summed over rays.
    pub counters: Counters,
    /// Per-ray state in bytes ([`Method::state_bytes`]).
    pub state_bytes: usize,
}

impl MethodReport {
    /// Mean active lanes per cycle over the warp width: 1 when no lane ever waits.
    pub fn simt_efficiency(&self) -> f64 {
        ratio(self.lane_steps, self.cycles * self.warp as u64)
    }

    /// Mean cycles per warp.
    pub fn cycles_per_warp(&self) -> f64 {
        ratio(self.cycles, self.warps as u64)
    }

    /// Mean latency-weighted cycles per warp ([`Self::latency_cycles`]).
    pub fn latency_cycles_per_warp(&self) -> f64 {
        ratio(self.latency_cycles, self.warps as u64)
    }

    /// Mean of a total per ray.
    pub fn per_ray(&self, total: u64) -> f64 {
        ratio(total, self.rays as u64)
    }

    /// Bytes per ray moved to and from a stack (4-byte node references pushed and popped);
    /// `None` for the stackless methods, which move none.
    pub fn stack_bytes_per_ray(&self) -> Option<f64> {
        matches!(self.method, Method::Bvh2(Bvh2Method::Stack) | Method::Bvh2(Bvh2Method::StackDisjoint))
            .then(|| self.per_ray(4 * (self.postponed + self.transitions.stack_pop)))
    }
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

/// A simulation's outputs: the report and what each ray found.
#[derive(Clone, Debug)]
pub struct MethodRun {
    /// Costs.
    pub report: MethodReport,
    /// Each ray's answer.
    pub hits: Vec<Hit>,
    /// Each ray's work counters.
    pub per_ray: Vec<Counters>,
    /// Each ray's visited nodes, when [`SimConfig::record_enumerations`].
    pub enumerations: Vec<Vec<NodeRef>>,
    /// The slowest warp's cycles, when [`SimConfig::record_timeline`].
    pub timeline: Vec<CycleRecord>,
}

/// Simulates `method` over `rays` in lockstep warps, with the watertight triangle test and the key
/// width the tree needs (`u32` or `u64`).
pub fn simulate(
    prepared: &PreparedScene,
    method: impl Into<Method>,
    rays: &[Ray],
    cfg: &SimConfig,
) -> Result<MethodRun, Error> {
    let method = method.into();
    match prepared.key_width() {
        KeyWidth::W32 => simulate_keyed::<u32>(prepared, method, rays, cfg),
        KeyWidth::W64 => simulate_keyed::<u64>(prepared, method, rays, cfg),
    }
}

fn simulate_keyed<K: Key>(
    prepared: &PreparedScene,
    method: Method,
    rays: &[Ray],
    cfg: &SimConfig,
) -> Result<MethodRun, Error> {
    // The simulator steps BVH2 traversals; another structure's method is an `Unsupported` error.
    let m = Bvh2Method::try_from(method)?;
    let mem = CountingMemory::new(prepared.memory(m)?);
    let root = prepared.root(m)?;
    let stats = prepared.bvh.stats();
    let sim = Sim { mem: &mem, root, cfg };
    let mut run = match m {
        Bvh2Method::Stack => sim.run::<StackState<false>>(rays),
        Bvh2Method::StackDisjoint => sim.run::<StackState<true>>(rays),
        Bvh2Method::ParentSibling => sim.run::<ParentSiblingState<K>>(rays),
        Bvh2Method::Uncle => sim.run::<RegisterState<K, UncleHops, false>>(rays),
        Bvh2Method::Hash => sim.run::<RegisterState<K, PerfectHashLookup, false>>(rays),
        Bvh2Method::HashDisjoint => sim.run::<RegisterState<K, PerfectHashLookup, true>>(rays),
        Bvh2Method::HashResume => sim.run::<Resuming<K>>(rays),
    };
    run.report.method = method;
    run.report.traffic = mem.traffic();
    run.report.state_bytes = method.state_bytes(stats.depth, K::WIDTH.bytes());
    if !matches!(method, Method::Bvh2(Bvh2Method::Stack) | Method::Bvh2(Bvh2Method::StackDisjoint)) {
        run.report.peak_stack = 0;
    }
    Ok(run)
}

/// What a lane's observer saw during one step, besides the running counters.
#[derive(Clone, Copy, Debug, Default)]
struct StepEvents {
    node: Option<NodeRef>,
    backtrack: Option<Backtrack>,
    link_reads: u32,
}

/// Per-lane observer: the core's counters, the current step's events and, optionally, the
/// enumeration.
#[derive(Debug, Default)]
struct LaneObserver {
    counters: Counters,
    step: StepEvents,
    nodes: Option<Vec<NodeRef>>,
}

impl Observer for LaneObserver {
    fn node(&mut self, node: NodeRef) {
        self.counters.node(node);
        self.step.node = Some(node);
        if let Some(n) = &mut self.nodes {
            n.push(node);
        }
    }
    fn primitive(&mut self, prim: u32) {
        self.counters.primitive(prim);
    }
    fn hit(&mut self, prim: u32, t: f32) {
        self.counters.hit(prim, t);
    }
    fn backtrack(&mut self, levels: u32, via: Backtrack) {
        self.counters.backtrack(levels, via);
        self.step.backtrack = Some(via);
    }
    fn link_read(&mut self, node: NodeRef) {
        self.counters.link_read(node);
        self.step.link_reads += 1;
    }
}

/// One ray in a warp.
struct Lane<S> {
    ray: usize,
    state: S,
    ctx: RayContext<Watertight>,
    q: QueryState,
    obs: LaneObserver,
    steps: u32,
    live_stack: u32,
    done: bool,
}

struct Sim<'a, M: BvhMemory> {
    mem: &'a CountingMemory<M>,
    root: TraceRoot,
    cfg: &'a SimConfig,
}

impl<M: BvhMemory> Sim<'_, M> {
    fn run<S: Machine>(&self, rays: &[Ray]) -> MethodRun {
        let warp = self.cfg.warp.max(1);
        let mut out = MethodRun {
            report: MethodReport {
                method: Method::Bvh2(Bvh2Method::Stack),
                rays: rays.len(),
                warp,
                warps: rays.len().div_ceil(warp),
                cycles: 0,
                latency_cycles: 0,
                lane_steps: 0,
                divergent_cycles: 0,
                transitions: TransitionCounts::default(),
                postponed: 0,
                peak_stack: 0,
                resumes: 0,
                traffic: Traffic::default(),
                counters: Counters::default(),
                state_bytes: 0,
            },
            hits: vec![Hit::MISS; rays.len()],
            per_ray: vec![Counters::default(); rays.len()],
            enumerations: if self.cfg.record_enumerations { vec![Vec::new(); rays.len()] } else { Vec::new() },
            timeline: Vec::new(),
        };
        for (w, chunk) in rays.chunks(warp).enumerate() {
            let mut timeline = self.cfg.record_timeline.then(Vec::new);
            self.run_warp::<S>(w * warp, chunk, timeline.as_mut(), &mut out);
            if let Some(t) = timeline.filter(|t| t.len() > out.timeline.len()) {
                out.timeline = t;
            }
        }
        out.report.counters.rays = rays.len() as u64;
        out
    }

    fn run_warp<S: Machine>(
        &self,
        first: usize,
        rays: &[Ray],
        mut timeline: Option<&mut Vec<CycleRecord>>,
        out: &mut MethodRun,
    ) {
        let record_lanes = timeline.is_some();
        let mut lanes: Vec<Lane<S>> = rays
            .iter()
            .enumerate()
            .map(|(i, ray)| {
                let ctx = RayContext::new(ray, self.root.scene_scale);
                Lane {
                    ray: first + i,
                    state: S::start(self.root.node),
                    q: QueryState::new(ray, self.cfg.query),
                    obs: LaneObserver { nodes: self.cfg.record_enumerations.then(Vec::new), ..LaneObserver::default() },
                    steps: 0,
                    live_stack: 0,
                    // As `trace_ray`: a ray that cannot hit anything, or whose distances overflow,
                    // visits nothing.
                    done: !ray.is_traceable() || !ctx.is_reliable(),
                    ctx,
                }
            })
            .collect();
        let r = &mut out.report;
        loop {
            let mut record = CycleRecord { active: 0, rounds: 0, lines: 0, lanes: Vec::new() };
            let (mut internal, mut leaf) = (false, false);
            for lane in &mut lanes {
                if lane.done {
                    if record_lanes {
                        record.lanes.push(Transition::Idle);
                    }
                    continue;
                }
                // The culling distance before the step: an internal node's step uses it unchanged.
                let limit = lane.q.limit();
                lane.obs.step = StepEvents::default();
                let hash_reads = self.mem.hash_reads();
                let (step, resumed) = lane.state.step(self.mem, &lane.ctx, &mut lane.q, &mut lane.obs);
                let ev = lane.obs.step;
                // Lanes step one after another here, so the counter's growth is this lane's.
                let rounds = 1 + ev.link_reads + (self.mem.hash_reads() - hash_reads) as u32;
                record.rounds = record.rounds.max(rounds);
                lane.steps += 1;
                record.active += 1;
                r.resumes += resumed as u64;
                let is_leaf = ev.node.is_some_and(NodeRef::is_leaf);
                if let Some(n) = ev.node.filter(|n| !n.is_leaf()) {
                    internal = true;
                    r.transitions.internal += 1;
                    // Re-derive (without counting the read) whether both children were hit: the
                    // stack methods push then, the others fill the register.
                    let node = self.mem.inner().node(n.index());
                    if let Descent::Both { .. } = order_children(&node, &lane.ctx, limit) {
                        r.postponed += 1;
                        lane.live_stack += 1;
                        r.peak_stack = r.peak_stack.max(lane.live_stack);
                    }
                } else if is_leaf {
                    leaf = true;
                    r.transitions.leaf += 1;
                }
                let t = match ev.backtrack {
                    Some(b) => {
                        match b {
                            Backtrack::StackPop => {
                                r.transitions.stack_pop += 1;
                                lane.live_stack = lane.live_stack.saturating_sub(1);
                            }
                            Backtrack::Register(_) => r.transitions.register += 1,
                            Backtrack::Hash { .. } => r.transitions.hash += 1,
                            Backtrack::Iterative => r.transitions.iterative += 1,
                            // Only kd methods restart, and they are not simulated.
                            Backtrack::Restart => r.transitions.iterative += 1,
                        }
                        Transition::Backtrack { leaf: is_leaf, via: b }
                    }
                    None if is_leaf => Transition::Leaf,
                    None => Transition::Internal,
                };
                if record_lanes {
                    record.lanes.push(t);
                }
                // The same step budget as `trace_ray`: binds only on damaged tables.
                if step == Step::Done || lane.steps > self.root.max_steps {
                    lane.done = true;
                }
            }
            if record.active == 0 {
                break;
            }
            record.lines = self.mem.end_cycle();
            r.cycles += 1;
            r.latency_cycles += u64::from(record.rounds);
            r.lane_steps += u64::from(record.active);
            r.divergent_cycles += (internal && leaf) as u64;
            if let Some(t) = timeline.as_mut() {
                t.push(record);
            }
        }
        for lane in lanes {
            out.hits[lane.ray] = lane.q.hit;
            out.report.counters.add(&lane.obs.counters);
            out.per_ray[lane.ray] = lane.obs.counters;
            if let Some(n) = lane.obs.nodes {
                out.enumerations[lane.ray] = n;
            }
        }
    }
}
