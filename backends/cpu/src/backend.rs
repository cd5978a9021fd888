use crate::dispatch::{trace_chunk, Chunk};
use rayon::prelude::*;
use raytrail_core::observe::Counters;
use raytrail_core::prepared::PreparedBvh2;
use raytrail_core::trace::{Record, Report, Trace, TraceOptions};
use raytrail_core::traverse::Family;
use raytrail_core::{Error, Hit, Ray};
use std::sync::Arc;
use std::time::Instant;

/// Rays per parallel task: large enough to amortize scheduling, small enough to balance load.
const CHUNK: usize = 256;

/// The rayon backend. Uses rayon's global pool unless built with a thread count.
#[derive(Debug, Default)]
pub struct CpuBackend {
    pool: Option<rayon::ThreadPool>,
}

/// A scene as the CPU backend holds it: shared, read in place.
#[derive(Clone, Debug)]
pub struct CpuScene(pub Arc<PreparedBvh2>);

impl CpuBackend {
    /// A backend on rayon's global pool (all cores).
    pub fn new() -> Self {
        Self { pool: None }
    }

    /// A backend on its own pool of `threads` threads (1: single-threaded).
    pub fn with_threads(threads: usize) -> Result<Self, rayon::ThreadPoolBuildError> {
        Ok(Self { pool: Some(rayon::ThreadPoolBuilder::new().num_threads(threads.max(1)).build()?) })
    }

    /// Threads this backend traces with.
    pub fn threads(&self) -> usize {
        self.pool.as_ref().map_or_else(rayon::current_num_threads, |p| p.current_num_threads())
    }

    fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
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

    fn prepare(&self, scene: Arc<PreparedBvh2>) -> Result<CpuScene, Error> {
        Ok(CpuScene(scene))
    }

    fn trace(&self, scene: &CpuScene, rays: &[Ray], opts: &TraceOptions, hits: &mut [Hit]) -> Result<Report, Error> {
        if rays.len() != hits.len() {
            return Err(Error::BufferMismatch { rays: rays.len(), hits: hits.len() });
        }
        // Fail before timing if the scene lacks what the method needs.
        match opts.method.family() {
            Family::Bvh2 => scene.0.memory(opts.method).map(|_| ())?,
            Family::Kd => scene.0.kd_memory().map(|_| ())?,
        }
        let mut enumerations: Vec<Vec<u32>> =
            if opts.record == Record::Enumerations { vec![Vec::new(); rays.len()] } else { Vec::new() };
        let start = Instant::now();
        let counters = self.install(|| {
            let record = opts.record == Record::Enumerations;
            let enum_chunks: Vec<&mut [Vec<u32>]> =
                if record { enumerations.chunks_mut(CHUNK).collect() } else { Vec::new() };
            let mut enum_chunks = enum_chunks.into_iter().map(Some).collect::<Vec<_>>();
            if !record {
                enum_chunks.resize_with(rays.len().div_ceil(CHUNK), || None);
            }
            rays.par_chunks(CHUNK)
                .zip(hits.par_chunks_mut(CHUNK))
                .zip(enum_chunks.into_par_iter())
                .map(|((rays, hits), e)| {
                    trace_chunk(&scene.0, opts, Chunk { rays, hits, enumerations: e.unwrap_or(&mut []) })
                })
                .try_reduce(Counters::default, |mut a, b| {
                    a.add(&b);
                    Ok(a)
                })
        })?;
        let seconds = start.elapsed().as_secs_f64();
        Ok(Report {
            rays: rays.len(),
            seconds,
            counters: (opts.record != Record::Nothing).then_some(counters),
            enumerations,
        })
    }
}
