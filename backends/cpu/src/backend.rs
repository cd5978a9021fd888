use crate::chunk::Chunk;
use crate::trace_order::SortScratch;
use rayon::prelude::*;
use raytrail_core::all_hits::{AllHits, AllHitsOptions};
use raytrail_core::method::Method;
use raytrail_core::method::WideWalk;
use raytrail_core::nearest::NearestPoint;
use raytrail_core::observe::Counters;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{check_buffers, Record, Report, Trace, TraceOptions};
use raytrail_core::trace_order::TraceOrder;
use raytrail_core::traverse::packets::GROUPING_RAYS;
use raytrail_core::wide::STREAM_RAYS;
use raytrail_core::{Error, Hit, Ray};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Rays per parallel task: large enough to amortize scheduling, small enough to balance load, and
/// one packet-grouping span, so that packets never cross two tasks.
const TASK_RAYS: usize = GROUPING_RAYS;

/// Rays per parallel task for `method`: [`TASK_RAYS`], or for a stream method one stream, so that
/// each task traces a whole one.
fn chunk_rays(method: Method) -> usize {
    if method.wide().is_some_and(|m| m.walk() == WideWalk::RayLists) {
        STREAM_RAYS
    } else {
        TASK_RAYS
    }
}

/// The rayon backend. Uses rayon's global pool unless built with a thread count.
#[derive(Debug, Default)]
pub struct CpuBackend {
    pool: Option<rayon::ThreadPool>,
    /// The buffers of sorted traces ([`crate::trace_order`]), kept from one batch to the next.
    pub(crate) sort_buffers: SortScratch,
}

/// A scene as the CPU backend holds it: shared, read in place.
#[derive(Clone, Debug)]
pub struct CpuScene(pub Arc<PreparedScene>);

impl CpuBackend {
    /// A backend on rayon's global pool (all cores).
    pub fn new() -> Self {
        Self { pool: None, sort_buffers: SortScratch::default() }
    }

    /// A backend on its own pool of `threads` threads (1: single-threaded).
    pub fn with_threads(threads: usize) -> Result<Self, rayon::ThreadPoolBuildError> {
        Ok(Self {
            pool: Some(rayon::ThreadPoolBuilder::new().num_threads(threads.max(1)).build()?),
            sort_buffers: SortScratch::default(),
        })
    }

    /// Threads this backend traces with.
    pub fn threads(&self) -> usize {
        self.pool.as_ref().map_or_else(rayon::current_num_threads, |p| p.current_num_threads())
    }

    /// Runs `f` on this backend's pool (on the caller's pool where it has none), so that rayon
    /// work `f` starts runs on the threads the backend was given.
    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        match &self.pool {
            Some(p) => p.install(f),
            None => f(),
        }
    }
}

impl Trace for CpuBackend {
    type Prepared = CpuScene;

    fn name(&self) -> &str {
        "cpu"
    }

    /// Every BVH2, kd, wide-BVH and stream method.
    fn supports(&self, method: Method) -> bool {
        matches!(method, Method::Bvh2(_) | Method::Kd(_) | Method::Wide(_) | Method::Stream(_))
    }

    fn prepare(&self, scene: Arc<PreparedScene>) -> Result<CpuScene, Error> {
        Ok(CpuScene(scene))
    }

    /// Traces the batch as given, each task first checking that its rays need no framing (while
    /// they are in cache: a pass of its own over a batch cost a tenth of a fast method's trace of
    /// primary rays); where one does, the batch is framed and traced again.
    fn trace(&self, scene: &CpuScene, rays: &[Ray], opts: &TraceOptions, hits: &mut [Hit]) -> Result<Report, Error> {
        // The stream method sorts the rays its own way (Garanzha & Loop's ray hashing).
        if opts.order == TraceOrder::Sorted && !matches!(opts.method, Method::Stream(_)) {
            return crate::trace_order::trace_sorted(self, scene, rays, opts, hits);
        }
        if let Some(report) = self.trace_in_frame(scene, rays, opts, hits, Framing::Check)? {
            return Ok(report);
        }
        raytrail_core::trace::trace_framed(&scene.0, rays, hits, |rays, hits| {
            self.trace_in_frame(scene, rays, opts, hits, Framing::Done)?
                .ok_or_else(|| Error::Device { backend: "cpu", detail: "framed rays asked for framing again".into() })
        })
    }

    /// Chunks of rays on the backend's threads, their lists joined in ray order.
    fn all_hits(&self, scene: &CpuScene, rays: &[Ray], options: &AllHitsOptions) -> Result<AllHits, Error> {
        self.trace_all_hits(scene, rays, options)
    }

    /// Chunks of points on the backend's threads.
    fn nearest_points(
        &self,
        scene: &CpuScene,
        points: &[[f32; 3]],
        radius: f32,
    ) -> Result<Vec<Option<NearestPoint>>, Error> {
        self.trace_nearest_points(scene, points, radius)
    }
}

/// Whether [`CpuBackend::trace_in_frame`] checks that its rays need no framing.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Framing {
    /// Check each task's rays; `None` where one needs framing.
    Check,
    /// The rays are framed already.
    Done,
}

impl CpuBackend {
    /// [`Trace::trace`] on rays in the scene's frame: framed already, or checked to need no
    /// framing (`None`, with nothing reliable traced, where a ray does).
    fn trace_in_frame(
        &self,
        scene: &CpuScene,
        rays: &[Ray],
        opts: &TraceOptions,
        hits: &mut [Hit],
        framing: Framing,
    ) -> Result<Option<Report>, Error> {
        check_buffers(rays, hits)?;
        if !self.supports(opts.method) {
            return Err(Error::Unsupported { method: opts.method.name(), by: "the CPU backend" });
        }
        // Fail before timing if the scene lacks what the method needs.
        scene.0.check_prepared(opts.method)?;
        if let Method::Stream(m) = opts.method {
            // The batch as a whole: its stages are the parallel part.
            let mut untraceable = 0;
            if framing == Framing::Check {
                let (needs_framing, n) = self.install(|| {
                    rays.par_chunks(TASK_RAYS)
                        .map(|c| scene.0.check_rays(c))
                        .fold(|| (false, 0), |(f, n), c| (f | c.needs_framing, n + c.untraceable))
                        .reduce(|| (false, 0), |a, b| (a.0 | b.0, a.1 + b.1))
                });
                if needs_framing {
                    return Ok(None);
                }
                untraceable = n;
            }
            let start = Instant::now();
            let out = self.install(|| crate::stream::trace(&scene.0, m, opts, rays, hits))?;
            let mut report = Report::new(rays.len(), start.elapsed().as_secs_f64());
            // Framed rays are counted by `trace_framed`, which has the caller's.
            report.untraceable = untraceable;
            report.counters = out.counters.map(|mut c| {
                c.rays = rays.len() as u64;
                c
            });
            report.enumerations = out.enumerations;
            report.stream = Some(out.stats);
            return Ok(Some(report));
        }
        let unframed = AtomicBool::new(false);
        let untraceable = AtomicUsize::new(0);
        let chunk = chunk_rays(opts.method);
        let mut enumerations: Vec<Vec<u32>> =
            if opts.record == Record::Enumerations { vec![Vec::new(); rays.len()] } else { Vec::new() };
        let start = Instant::now();
        let counters = self.install(|| {
            let record = opts.record == Record::Enumerations;
            let enum_chunks: Vec<&mut [Vec<u32>]> =
                if record { enumerations.chunks_mut(chunk).collect() } else { Vec::new() };
            let mut enum_chunks = enum_chunks.into_iter().map(Some).collect::<Vec<_>>();
            if !record {
                enum_chunks.resize_with(rays.len().div_ceil(chunk), || None);
            }
            rays.par_chunks(chunk)
                .zip(hits.par_chunks_mut(chunk))
                .zip(enum_chunks.into_par_iter())
                .map(|((rays, hits), e)| {
                    if framing == Framing::Check {
                        let check = scene.0.check_rays(rays);
                        if check.needs_framing {
                            unframed.store(true, Ordering::Relaxed);
                        }
                        untraceable.fetch_add(check.untraceable, Ordering::Relaxed);
                    }
                    if unframed.load(Ordering::Relaxed) {
                        return Ok(Counters::default());
                    }
                    trace_chunk(&scene.0, opts, Chunk { rays, hits, enumerations: e.unwrap_or(&mut []) })
                })
                .try_reduce(Counters::default, |mut a, b| {
                    a.add(&b);
                    Ok(a)
                })
        })?;
        if unframed.load(Ordering::Relaxed) {
            return Ok(None);
        }
        let seconds = start.elapsed().as_secs_f64();
        let mut report = Report::new(rays.len(), seconds);
        // Framed rays are counted by `trace_framed`, which has the caller's.
        report.untraceable = untraceable.into_inner();
        report.counters = (opts.record != Record::Nothing).then_some(counters);
        report.enumerations = (opts.record == Record::Enumerations).then_some(enumerations);
        Ok(Some(report))
    }
}

/// Traces one chunk with the loop of the method's structure.
fn trace_chunk(scene: &PreparedScene, opts: &TraceOptions, chunk: Chunk<'_>) -> Result<Counters, Error> {
    match opts.method {
        Method::Bvh2(m) => crate::bvh2::trace_chunk(scene, m, opts, chunk),
        Method::Kd(m) => crate::kd::trace_chunk(scene, m, opts, chunk),
        Method::Wide(m) => crate::wide::trace_chunk(scene, m, opts, chunk),
        other => Err(Error::Unsupported { method: other.name(), by: "the CPU backend" }),
    }
}
