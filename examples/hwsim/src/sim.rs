//! The lockstep driver: rays in warps of `W` lanes, every unfinished lane making one transition
//! per cycle, with what each transition was and what it read. The driver is the same for every
//! structure; what a lane is and how it steps comes from a `Stepper` (`stepper.rs`).

use crate::bvh2_lanes::simulate_bvh2;
use crate::kd_lanes::simulate_kd;
use crate::memory::Traffic;
use crate::stepper::{Outcome, Stepper};
use crate::trail_lanes::simulate_trail;
use crate::wide_lanes::simulate_wide;
use raytrail_core::bvh2::NodeRef;
use raytrail_core::method::WideWalk;
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
    /// `r` register, `h` hash, `w` walk over links (iterative), `x` restart (kd), upper case after
    /// a leaf.
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
    /// Stack pops (one per backtracking step served by the stack; a wide traversal may pop and
    /// drop several entries in one step).
    pub stack_pop: u64,
    /// ... by the most-recently-postponed-node register.
    pub register: u64,
    /// ... by the perfect hash.
    pub hash: u64,
    /// ... by walking parent or uncle links.
    pub iterative: u64,
    /// ... by descending again from the root or a pushed-down node (kd-restart, push-down, and
    /// short-stack when its stack runs empty).
    pub restart: u64,
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
    /// that tells constant-time from iterative backtracking, which [`Self::cycles`] cannot. A kd
    /// leaf's node, its primitive references and their triangles are three dependent reads.
    pub latency_cycles: u64,
    /// Dependent reads summed over lane-steps (each step's chain, as for
    /// [`Self::latency_cycles`]): the memory round trips a ray waits for one after another.
    pub dependent_reads: u64,
    /// The longest chain of dependent reads in any one step.
    pub max_chain: u32,
    /// Lane-steps over all cycles (the sum of active lanes).
    pub lane_steps: u64,
    /// Cycles in which some lanes processed internal nodes and others leaves: the two are
    /// different code paths, so a SIMT machine would serialize them.
    pub divergent_cycles: u64,
    /// Transitions by kind.
    pub transitions: TransitionCounts,
    /// Nodes postponed (more than one child entered): stack pushes for the stack methods,
    /// register writes for the BVH2 register methods, hit children beyond the first for a wide
    /// node, far children for the kd methods (pushed, or left to a restart).
    pub postponed: u64,
    /// Entries written to a stack (kd short-stack: including those later pushed off its bottom).
    pub stack_pushes: u64,
    /// Bytes of one stack entry: a 4-byte node reference (BVH2), reference and segment (kd, 12 B),
    /// reference and entry distance (wide, 8 B); 0 for a method without a stack.
    pub stack_entry_bytes: u64,
    /// Steps where the kd lanes' model of the machine's segment and stack disagreed with the
    /// machine (see `kd_lanes`); 0 unless the model is wrong, and always 0 for other structures.
    pub stack_model_mismatches: u64,
    /// Most stack entries live at once in any ray (pushes minus pops and drops; for
    /// stack-disjoint an upper bound, since its hits drop entries without popping them). Zero for
    /// stackless methods.
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

    /// Bytes per ray moved to and from a stack (entries pushed and popped); `None` for the
    /// stackless methods, which move none.
    pub fn stack_bytes_per_ray(&self) -> Option<f64> {
        (self.stack_entry_bytes > 0)
            .then(|| self.per_ray(self.stack_entry_bytes * (self.stack_pushes + self.transitions.stack_pop)))
    }

    /// Mean dependent reads per ray ([`Self::dependent_reads`]).
    pub fn dependent_reads_per_ray(&self) -> f64 {
        self.per_ray(self.dependent_reads)
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

/// Simulates `method` over `rays` in lockstep warps, with the watertight triangle test: any BVH2
/// method (with the key width the tree needs), the kd methods but the packet one, and every wide
/// method whose rays walk alone (the stack walks and the stackless `bvh4-hash`). kd-packet and the
/// wide packet and ray-list methods are lockstep units of their own (rays sharing a node): they
/// are an [`Error::Unsupported`], as is a method `prepared` lacks the tables of
/// ([`Error::NotPrepared`]).
pub fn simulate(
    prepared: &PreparedScene,
    method: impl Into<Method>,
    rays: &[Ray],
    cfg: &SimConfig,
) -> Result<MethodRun, Error> {
    let method = method.into();
    let mut run = match method {
        Method::Bvh2(m) => simulate_bvh2(prepared, m, rays, cfg)?,
        Method::Kd(m) => simulate_kd(prepared, m, rays, cfg)?,
        Method::Wide(m) if m.walk() == WideWalk::Stack => simulate_wide(prepared, m, rays, cfg)?,
        Method::Wide(m) if m.walk() == WideWalk::Trail => simulate_trail(prepared, m, rays, cfg)?,
        _ => return Err(Error::Unsupported { method: method.name(), by: "the lockstep simulator" }),
    };
    run.report.method = method;
    run.report.state_bytes = prepared.state_bytes(method);
    if run.report.stack_entry_bytes == 0 {
        run.report.peak_stack = 0;
    }
    Ok(run)
}

/// What a lane's observer saw during one step, besides the running counters.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct StepEvents {
    /// The node or leaf the step processed.
    pub node: Option<NodeRef>,
    /// The backtracking step it ended with, if any.
    pub backtrack: Option<Backtrack>,
    /// Node records read to follow links.
    pub link_reads: u32,
    /// Stack entries popped (a wide traversal pops and drops entries that can no longer hold a
    /// closer hit, several in one step).
    pub pops: u32,
}

/// Per-lane observer: the core's counters, the current step's events and, optionally, the
/// enumeration.
#[derive(Debug, Default)]
pub(crate) struct LaneObserver {
    counters: Counters,
    /// This step's events.
    pub step: StepEvents,
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
        self.step.pops += (via == Backtrack::StackPop) as u32;
    }
    fn link_read(&mut self, node: NodeRef) {
        self.counters.link_read(node);
        self.step.link_reads += 1;
    }
}

/// One ray in a warp.
struct Lane<L> {
    ray: usize,
    /// The structure's per-ray state; `None` for a ray that visits nothing.
    state: Option<L>,
    q: QueryState,
    obs: LaneObserver,
    steps: u32,
    live_stack: u32,
    done: bool,
}

/// Runs `stepper` over `rays` in warps; the report's method and state bytes are the caller's to
/// fill.
pub(crate) fn drive<S: Stepper>(stepper: &S, rays: &[Ray], cfg: &SimConfig) -> MethodRun {
    let warp = cfg.warp.max(1);
    let mut out = MethodRun {
        report: MethodReport {
            method: Method::Bvh2(Bvh2Method::Stack),
            rays: rays.len(),
            warp,
            warps: rays.len().div_ceil(warp),
            cycles: 0,
            latency_cycles: 0,
            dependent_reads: 0,
            max_chain: 0,
            lane_steps: 0,
            divergent_cycles: 0,
            transitions: TransitionCounts::default(),
            postponed: 0,
            stack_pushes: 0,
            stack_entry_bytes: stepper.stack_entry_bytes(),
            stack_model_mismatches: 0,
            peak_stack: 0,
            resumes: 0,
            traffic: Traffic::default(),
            counters: Counters::default(),
            state_bytes: 0,
        },
        hits: vec![Hit::MISS; rays.len()],
        per_ray: vec![Counters::default(); rays.len()],
        enumerations: if cfg.record_enumerations { vec![Vec::new(); rays.len()] } else { Vec::new() },
        timeline: Vec::new(),
    };
    for (w, chunk) in rays.chunks(warp).enumerate() {
        let mut timeline = cfg.record_timeline.then(Vec::new);
        run_warp(stepper, cfg, w * warp, chunk, timeline.as_mut(), &mut out);
        if let Some(t) = timeline.filter(|t| t.len() > out.timeline.len()) {
            out.timeline = t;
        }
    }
    out.report.counters.rays = rays.len() as u64;
    out.report.traffic = stepper.traffic();
    out
}

fn run_warp<S: Stepper>(
    stepper: &S,
    cfg: &SimConfig,
    first: usize,
    rays: &[Ray],
    mut timeline: Option<&mut Vec<CycleRecord>>,
    out: &mut MethodRun,
) {
    let record_lanes = timeline.is_some();
    let mut lanes: Vec<Lane<S::Lane>> = rays
        .iter()
        .enumerate()
        .map(|(i, ray)| {
            // As the CPU backend: a ray its structure turns away (not traceable, distances that
            // overflow, missing the kd-tree's box) visits nothing.
            let state = stepper.begin(ray);
            Lane {
                ray: first + i,
                done: state.is_none(),
                state,
                q: QueryState::new(ray, cfg.query),
                obs: LaneObserver { nodes: cfg.record_enumerations.then(Vec::new), ..LaneObserver::default() },
                steps: 0,
                live_stack: 0,
            }
        })
        .collect();
    let r = &mut out.report;
    loop {
        let mut record = CycleRecord { active: 0, rounds: 0, lines: 0, lanes: Vec::new() };
        let (mut internal, mut leaf) = (false, false);
        for lane in &mut lanes {
            let Some(state) = lane.state.as_mut().filter(|_| !lane.done) else {
                if record_lanes {
                    record.lanes.push(Transition::Idle);
                }
                continue;
            };
            lane.obs.step = StepEvents::default();
            let Outcome { step, resumed, postponed, pushed, dropped, rounds } =
                stepper.step(state, &mut lane.q, &mut lane.obs);
            let ev = lane.obs.step;
            record.rounds = record.rounds.max(rounds);
            r.dependent_reads += u64::from(rounds);
            r.max_chain = r.max_chain.max(rounds);
            lane.steps += 1;
            record.active += 1;
            r.resumes += resumed as u64;
            r.postponed += u64::from(postponed);
            r.stack_pushes += u64::from(pushed);
            lane.live_stack = (lane.live_stack + pushed).saturating_sub(dropped);
            r.peak_stack = r.peak_stack.max(lane.live_stack);
            let is_leaf = ev.node.is_some_and(NodeRef::is_leaf);
            if ev.node.is_some_and(|n| !n.is_leaf()) {
                internal = true;
                r.transitions.internal += 1;
            } else if is_leaf {
                leaf = true;
                r.transitions.leaf += 1;
            }
            let t = match ev.backtrack {
                Some(b) => {
                    match b {
                        Backtrack::StackPop => {
                            r.transitions.stack_pop += u64::from(ev.pops);
                            lane.live_stack = lane.live_stack.saturating_sub(ev.pops);
                        }
                        Backtrack::Register(_) => r.transitions.register += 1,
                        Backtrack::Hash { .. } => r.transitions.hash += 1,
                        Backtrack::Iterative => r.transitions.iterative += 1,
                        Backtrack::Restart => r.transitions.restart += 1,
                    }
                    Transition::Backtrack { leaf: is_leaf, via: b }
                }
                None if is_leaf => Transition::Leaf,
                None => Transition::Internal,
            };
            if record_lanes {
                record.lanes.push(t);
            }
            // The same step budget as the CPU backend's loops: binds only on damaged tables.
            if step == Step::Done || lane.steps > stepper.max_steps() {
                lane.done = true;
            }
        }
        if record.active == 0 {
            break;
        }
        record.lines = stepper.end_cycle();
        r.cycles += 1;
        r.latency_cycles += u64::from(record.rounds);
        r.lane_steps += u64::from(record.active);
        r.divergent_cycles += (internal && leaf) as u64;
        if let Some(t) = timeline.as_mut() {
            t.push(record);
        }
    }
    for lane in lanes {
        out.hits[lane.ray] = lane.q.hit();
        out.report.counters.add(&lane.obs.counters);
        out.per_ray[lane.ray] = lane.obs.counters;
        if let Some(n) = lane.obs.nodes {
            out.enumerations[lane.ray] = n;
        }
    }
}
