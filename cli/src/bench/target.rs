//! Bench targets: anything that traces a batch of rays into hits. raytrail's methods on a backend
//! are targets, and so is each peer library; a new backend (wgpu) adds its own target type.

use raytrail::core::method::{Method, Query, Structure};
use raytrail::core::observe::Counters;
use raytrail::core::stream::{StreamParams, StreamStats};
use raytrail::core::trace::{Record, Trace, TraceOptions};
use raytrail::core::trace_order::TraceOrder;
use raytrail::core::{Hit, Ray};
use raytrail::cpu::{CpuBackend, CpuScene};
use raytrail::gpu::KernelTiming;

/// What a target is, for grouping and colouring.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetKind {
    /// A raytrail method over the BVH2.
    RaytrailBvh2,
    /// A raytrail method over the kd-tree.
    RaytrailKd,
    /// A raytrail method over a wide BVH.
    RaytrailWide,
    /// raytrail's ray-stream method.
    RaytrailStream,
    /// raytrail's `--method auto`: a method chosen per batch.
    RaytrailAuto,
    /// A raytrail method on the GPU (wgpu backend).
    RaytrailGpu,
    /// A peer library with its own triangle test.
    PeerOwnTest,
    /// A peer library's traversal with raytrail's watertight triangle test in its callback.
    PeerWatertight,
}

impl TargetKind {
    /// Name in JSON.
    pub fn name(self) -> &'static str {
        match self {
            TargetKind::RaytrailBvh2 => "raytrail-bvh2",
            TargetKind::RaytrailKd => "raytrail-kd",
            TargetKind::RaytrailWide => "raytrail-wide",
            TargetKind::RaytrailStream => "raytrail-stream",
            TargetKind::RaytrailAuto => "raytrail-auto",
            TargetKind::RaytrailGpu => "raytrail-gpu",
            TargetKind::PeerOwnTest => "peer",
            TargetKind::PeerWatertight => "peer-watertight",
        }
    }

    /// Whether the target is one of raytrail's CPU methods (what the speed target compares).
    pub fn is_raytrail(self) -> bool {
        matches!(
            self,
            TargetKind::RaytrailBvh2
                | TargetKind::RaytrailKd
                | TargetKind::RaytrailWide
                | TargetKind::RaytrailStream
                | TargetKind::RaytrailAuto
        )
    }

    /// Whether the target is a peer library.
    pub fn is_peer(self) -> bool {
        matches!(self, TargetKind::PeerOwnTest | TargetKind::PeerWatertight)
    }
}

/// Work per ray, where a target can count it (in a separate, untimed pass).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Work {
    /// Nodes visited (internal and leaves) per ray.
    pub nodes: Option<f64>,
    /// Leaves visited per ray.
    pub leaves: Option<f64>,
    /// Ray/triangle tests per ray.
    pub tests: Option<f64>,
}

/// Something the bench can time: traces rays into hits on a given thread pool.
pub trait BenchTarget: Send + Sync {
    /// Name in tables, JSON and plots; `--baseline` matches it.
    fn name(&self) -> &str;
    /// Group of the target.
    fn kind(&self) -> TargetKind;
    /// Traces `rays` into `hits` (same length) with `query`, parallel over `pool`'s threads.
    fn trace(&self, pool: &rayon::ThreadPool, rays: &[Ray], query: Query, hits: &mut [Hit]) -> Result<(), String>;
    /// Traces as [`BenchTarget::trace`]; returns the seconds the target timed itself (GPU
    /// timestamps), or `None` to be timed by the wall clock around the call.
    fn trace_timed(
        &self,
        pool: &rayon::ThreadPool,
        rays: &[Ray],
        query: Query,
        hits: &mut [Hit],
    ) -> Result<Option<f64>, String> {
        self.trace(pool, rays, query, hits).map(|_| None)
    }
    /// Whether each timed pass must follow a spell of untimed load (a GPU, whose clocks drop while
    /// the CPU targets run).
    fn needs_clock_spin(&self) -> bool {
        false
    }
    /// Counts the work per ray in an extra pass; `None` where the target cannot count.
    fn work(&self, pool: &rayon::ThreadPool, rays: &[Ray], query: Query) -> Result<Option<Work>, String>;
    /// A stream method's stage times and working figures, from one more untimed pass; `None` for
    /// every other target.
    fn stream_stats(
        &self,
        _pool: &rayon::ThreadPool,
        _rays: &[Ray],
        _query: Query,
    ) -> Result<Option<StreamStats>, String> {
        Ok(None)
    }
    /// A GPU target's kernel time at steady clocks (rays uploaded once, many passes between two
    /// timestamps); `None` for every other target.
    fn kernel_timing(&self, _rays: &[Ray], _query: Query) -> Result<Option<KernelTiming>, String> {
        Ok(None)
    }
}

/// Untimed passes a stream target's stage figures are taken from (the median one).
const STAGE_PASSES: usize = 3;

/// The targets of a run, in report order.
pub type Targets = Vec<Box<dyn BenchTarget>>;

/// A raytrail method on the CPU backend.
///
/// The backend is built without a pool of its own ([`CpuBackend::new`]) and called inside the
/// bench's pool, so raytrail and the peers share one rayon pool per thread count: the same
/// threads, the same scheduler.
pub struct RaytrailCpu {
    method: Method,
    name: String,
    stream: StreamParams,
    order: TraceOrder,
    backend: CpuBackend,
    scene: CpuScene,
}

impl RaytrailCpu {
    /// The target tracing `method` over `scene`.
    pub fn new(method: Method, scene: CpuScene) -> Self {
        Self {
            method,
            name: method.name().to_string(),
            stream: StreamParams::default(),
            order: TraceOrder::AsGiven,
            backend: CpuBackend::new(),
            scene,
        }
    }

    /// The same target tracing in `order`, named `METHOD/sorted` for [`TraceOrder::Sorted`].
    pub fn in_order(mut self, order: TraceOrder) -> Self {
        if order == TraceOrder::Sorted {
            self.name = format!("{}/sorted", self.name);
        }
        self.order = order;
        self
    }

    /// The stream method with `params`, named `stream` for the defaults and
    /// `stream/<packet>/<cell>` otherwise (a parameter study's targets).
    pub fn stream(method: Method, params: StreamParams, scene: CpuScene) -> Self {
        let name = if params == StreamParams::default() {
            method.name().to_string()
        } else {
            format!("{}/{}/{}", method.name(), params.max_packet, params.origin_cell_fraction)
        };
        Self { method, name, stream: params, order: TraceOrder::AsGiven, backend: CpuBackend::new(), scene }
    }

    /// The options of a trace with `query` recording `record`.
    fn options(&self, query: Query, record: Record) -> TraceOptions {
        TraceOptions::new(self.method).query(query).record(record).stream(self.stream).order(self.order)
    }

    /// Traces with `record`, returning the counters when recorded.
    fn run(
        &self,
        pool: &rayon::ThreadPool,
        rays: &[Ray],
        query: Query,
        hits: &mut [Hit],
        record: Record,
    ) -> Result<Option<Counters>, String> {
        let opts = self.options(query, record);
        let report = pool
            .install(|| self.backend.trace(&self.scene, rays, &opts, hits))
            .map_err(|e| format!("{}: {e}", self.name))?;
        Ok(report.counters)
    }
}

impl BenchTarget for RaytrailCpu {
    fn name(&self) -> &str {
        &self.name
    }

    fn kind(&self) -> TargetKind {
        match self.method.structure() {
            Structure::Kd => TargetKind::RaytrailKd,
            Structure::Wide => TargetKind::RaytrailWide,
            Structure::Levels => TargetKind::RaytrailStream,
            _ => TargetKind::RaytrailBvh2,
        }
    }

    fn trace(&self, pool: &rayon::ThreadPool, rays: &[Ray], query: Query, hits: &mut [Hit]) -> Result<(), String> {
        self.run(pool, rays, query, hits, Record::Nothing).map(|_| ())
    }

    fn work(&self, pool: &rayon::ThreadPool, rays: &[Ray], query: Query) -> Result<Option<Work>, String> {
        let mut hits = vec![Hit::MISS; rays.len()];
        let Some(c) = self.run(pool, rays, query, &mut hits, Record::Counters)? else { return Ok(None) };
        let per_ray = |x: u64| Some(x as f64 / c.rays.max(1) as f64);
        Ok(Some(Work { nodes: per_ray(c.nodes()), leaves: per_ray(c.leaves), tests: per_ray(c.primitive_tests) }))
    }

    fn stream_stats(
        &self,
        pool: &rayon::ThreadPool,
        rays: &[Ray],
        query: Query,
    ) -> Result<Option<StreamStats>, String> {
        if self.method.stream().is_none() {
            return Ok(None);
        }
        // Three untimed passes; the stages of the one with the median total (a single pass on a
        // shared machine is at the mercy of whatever else runs).
        let mut hits = vec![Hit::MISS; rays.len()];
        let opts = self.options(query, Record::Nothing);
        let mut runs = Vec::with_capacity(STAGE_PASSES);
        for _ in 0..STAGE_PASSES {
            let report = pool
                .install(|| self.backend.trace(&self.scene, rays, &opts, &mut hits))
                .map_err(|e| format!("{}: {e}", self.name))?;
            runs.extend(report.stream);
        }
        let total = |st: &StreamStats| {
            let s = st.seconds;
            s.sort + s.frustums + s.traversal + s.intersection
        };
        runs.sort_by(|a, b| total(a).total_cmp(&total(b)));
        Ok(runs.get(runs.len() / 2).cloned())
    }
}
