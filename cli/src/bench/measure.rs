//! Timing: every target on every ray batch at every thread count, passes interleaved.
//!
//! Per batch and thread count, each target first traces once untimed (the warm-up; at the first
//! thread count its hits are also compared with the reference). Then come the timed passes,
//! round-robin: pass 1 of every target, then pass 2 of every target, and so on, so that a slow
//! spell of the shared machine spreads over all targets instead of hitting one. A target's speed
//! is the median of its passes, timed by the wall clock around its trace call (GPU targets with
//! timestamp queries time themselves). A GPU pass takes about a millisecond, and between them the
//! CPU passes take seconds in which the GPU drops to idle clocks: interleaved, the same kernel
//! measured up to 5x slower from one row to the next on an H100. So a GPU target's passes run back
//! to back after [`CLOCK_SPIN`] of untimed tracing (which narrows the spread but does not remove
//! it: `docs/notes/*-benchmarks-h100-host.md`, "GPU Mrays/s on the H100"). Work per ray is counted
//! in one more untimed pass, on the largest pool.

use super::agreement::{compare, Agreement};
use super::rays::RayBatch;
use super::report::{RayReport, Row};
use super::target::BenchTarget;
use crate::median::median;
use crate::progress::Progress;
use raytrail::core::geometry::Triangle;
use raytrail::core::Hit;
use std::time::{Duration, Instant};

/// Untimed tracing before the timed passes of a target that asks for it (GPUs), so that they run
/// at the clocks a sustained load gets.
const CLOCK_SPIN: Duration = Duration::from_millis(250);

/// The fixed inputs of one scene's measurements.
pub struct Plan<'a> {
    /// Targets, in report order.
    pub targets: &'a [Box<dyn BenchTarget>],
    /// Thread pools with their thread counts, ascending.
    pub pools: &'a [(usize, rayon::ThreadPool)],
    /// Timed passes per measurement.
    pub passes: usize,
    /// Target the ratio divides by.
    pub baseline: &'a str,
    /// The scene's triangles (to classify disagreements).
    pub triangles: &'a [Triangle],
}

impl Plan<'_> {
    /// Progress steps [`Plan::run`] takes for one batch.
    pub fn steps_per_batch(&self) -> usize {
        self.targets.len() * (self.pools.len() * (1 + self.passes) + 1)
    }

    /// Measures every target on `batch`, comparing hits with `reference` (the stack method's).
    pub fn run(&self, batch: &RayBatch, reference: &[Hit], progress: &mut Progress) -> Result<RayReport, String> {
        let (rays, query, kind) = (&batch.rays, batch.kind.query(), batch.kind.name());
        let mut hits = vec![Hit::MISS; rays.len()];
        let mut agreement: Vec<(String, Agreement)> = Vec::new();
        let mut rows = Vec::new();
        for (p, (threads, pool)) in self.pools.iter().enumerate() {
            for t in self.targets {
                t.trace(pool, rays, query, &mut hits)?;
                if p == 0 {
                    agreement.push((t.name().to_string(), compare(query, rays, reference, &hits, self.triangles)));
                }
                progress.step(&format!("{kind} {} warm-up, {threads} thr", t.name()));
            }
            let mut times = vec![Vec::with_capacity(self.passes); self.targets.len()];
            for pass in 0..self.passes {
                for (t, secs) in self.targets.iter().zip(&mut times) {
                    // A GPU gets its passes back to back, after the spin, in the first round.
                    let (spin, count) = match (t.needs_clock_spin(), pass) {
                        (false, _) => (false, 1),
                        (true, 0) => (true, self.passes),
                        (true, _) => continue,
                    };
                    if spin {
                        let spin = Instant::now();
                        while spin.elapsed() < CLOCK_SPIN {
                            t.trace(pool, rays, query, &mut hits)?;
                        }
                    }
                    for k in 0..count {
                        let start = Instant::now();
                        let own = t.trace_timed(pool, rays, query, &mut hits)?;
                        secs.push(own.unwrap_or_else(|| start.elapsed().as_secs_f64()));
                        progress.step(&format!("{kind} {} pass {}, {threads} thr", t.name(), pass + k + 1));
                    }
                }
            }
            for (t, passes) in self.targets.iter().zip(times) {
                let median_s = median(&passes);
                let mrays_per_s = if median_s > 0.0 { rays.len() as f64 / median_s / 1e6 } else { 0.0 };
                rows.push(Row {
                    target: t.name().to_string(),
                    kind: t.kind(),
                    threads: *threads,
                    passes,
                    median_s,
                    mrays_per_s,
                    ratio: None,
                    work: None,
                    stream: None,
                    kernel: None,
                });
            }
        }
        if let Some((_, pool)) = self.pools.last() {
            for t in self.targets {
                let work = t.work(pool, rays, query)?;
                let stream = t.stream_stats(pool, rays, query)?;
                let kernel = t.kernel_timing(rays, query)?;
                for r in rows.iter_mut().filter(|r| r.target == t.name()) {
                    r.work = work;
                    r.stream.clone_from(&stream);
                    r.kernel.clone_from(&kernel);
                }
                progress.step(&format!("{kind} {} work", t.name()));
            }
        }
        set_ratios(&mut rows, self.baseline);
        Ok(RayReport { kind: batch.kind, rays: rays.len(), rows, agreement })
    }
}

/// Sets each row's ratio to the baseline's speed at the same thread count. The baseline
/// [`EMBREE_BEST`] is the faster of `embree` and `embree-high` on each batch and thread count.
fn set_ratios(rows: &mut [Row], baseline: &str) {
    let is_base = |target: &str| {
        if baseline == EMBREE_BEST {
            crate::bench::peers::is_embree(target)
        } else {
            target == baseline
        }
    };
    let speed = |threads: usize| {
        rows.iter()
            .filter(|r| r.threads == threads && is_base(&r.target) && r.mrays_per_s > 0.0)
            .map(|r| r.mrays_per_s)
            .reduce(f64::max)
    };
    let base: Vec<(usize, Option<f64>)> = rows.iter().map(|r| (r.threads, speed(r.threads))).collect();
    for (r, (_, b)) in rows.iter_mut().zip(base) {
        r.ratio = b.map(|b| r.mrays_per_s / b);
    }
}

/// The baseline that is the faster Embree peer per batch: `--baseline embree-best`, with both
/// `embree` and `embree-high` among the peers.
pub const EMBREE_BEST: &str = "embree-best";
