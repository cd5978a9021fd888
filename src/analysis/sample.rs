//! The sample of a batch that `auto` times its candidates on, and the CPU backend's clock.

use super::choice::{choose, Choice, Portion, SampleClock, CANDIDATES, ROUNDS};
use super::streams::{self, walks_lists};
use raytrail_core::method::{Method, Query};
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::wide::packet::WIDE_PACKET;
use raytrail_core::{Error, Hit, Ray};
use raytrail_cpu::{CpuBackend, CpuScene};

/// The sample is about this fraction of the batch: the first look traces a quarter of it ([`part`]) per
/// candidate, and where two candidates are close, three rounds each trace it whole: some eight
/// samples, about 5% of the batch, at the most; a clear winner costs about one sample.
pub const SAMPLE_FRACTION: usize = 160;

/// Fewest rays in a sample (below this a trace is too short to time: a few dozen microseconds).
pub const MIN_SAMPLE: usize = 512;

/// Most rays in a sample.
pub const MAX_SAMPLE: usize = 8192;

/// Contiguous runs a sample is made of, spread evenly over the batch. Sixteen, not four: the cost
/// per ray differs by region of an image, and by more between methods than the 10% `auto` may
/// lose. Four runs of 307 camera rays into the kitchen made kd-stack look 30% faster than bvh8,
/// which was 15% faster over the whole batch; sixteen runs of 77 ranked the two as the batch did
/// (`docs/notes/*-benchmarks-leaf-cost-and-auto-sample.md`, "`--method auto`: a sample of sixteen runs").
pub const SAMPLE_RUNS: usize = 16;

/// Runs of the sample, and their quarters in the first look, are whole multiples of this many
/// rays: a packet's worth ([`WIDE_PACKET`]), so that a packet method groups rays of one region of
/// the batch, as it does over the batch. Runs of 8 rays put four regions of an image into one
/// packet and hid the coherence `bvh8-packet` profits from.
pub const SAMPLE_RUN_UNIT: usize = WIDE_PACKET;

/// Rays in the sample of a batch of `n` rays: `n / SAMPLE_FRACTION` kept within
/// [`MIN_SAMPLE`]..=[`MAX_SAMPLE`] and rounded up to [`SAMPLE_RUNS`] runs of whole
/// [`SAMPLE_RUN_UNIT`]s, and never more than the batch.
pub fn sample_size(n: usize) -> usize {
    let runs = SAMPLE_RUNS * SAMPLE_RUN_UNIT;
    (n / SAMPLE_FRACTION).clamp(MIN_SAMPLE, MAX_SAMPLE).next_multiple_of(runs).min(n)
}

/// The sample of `rays`: [`SAMPLE_RUNS`] runs of consecutive rays, evenly spread, together
/// [`sample_size`] rays (the whole batch when it is that small). Runs rather than single rays
/// spread over the batch, because consecutive rays are neighbours in a coherent batch (Morton
/// order, several rays per pixel) and the methods that profit from coherence (the stream method's
/// packets) must see it; several runs, because one run might fall on a part of the image that
/// misses everything.
pub fn sample(rays: &[Ray]) -> Vec<Ray> {
    let n = rays.len();
    let size = sample_size(n);
    if size >= n {
        return rays.to_vec();
    }
    let run = size.div_ceil(SAMPLE_RUNS);
    let stride = n / SAMPLE_RUNS;
    let mut out = Vec::with_capacity(size);
    for k in 0..SAMPLE_RUNS {
        // Each run centred in its share of the batch.
        let start = k * stride + stride.saturating_sub(run) / 2;
        let take = run.min(size - out.len());
        out.extend_from_slice(&rays[start..(start + take).min(n)]);
    }
    out
}

/// Part of a sample for the first look: the first quarter of each of its runs, rounded up to a
/// whole [`SAMPLE_RUN_UNIT`], so that it comes from every region of the batch the sample does (one
/// run alone is one region of an image, where the methods may rank otherwise than over the whole).
pub fn part(sample: &[Ray]) -> Vec<Ray> {
    let run = sample.len().div_ceil(SAMPLE_RUNS).max(1);
    sample.chunks(run).flat_map(|r| &r[..quarter(r.len())]).copied().collect()
}

/// The first-look share of a run of `len` rays.
fn quarter(len: usize) -> usize {
    len.div_ceil(4).next_multiple_of(SAMPLE_RUN_UNIT).min(len)
}

/// Times traces of a sample on the CPU backend, with the backend's own clock (which leaves out
/// allocating the hits).
pub struct CpuClock<'a> {
    backend: &'a CpuBackend,
    scene: &'a CpuScene,
    rays: &'a [Ray],
    part: Vec<Ray>,
    query: Query,
    hits: Vec<Hit>,
}

impl<'a> CpuClock<'a> {
    /// The clock of `rays` (a [`sample`]) traced with `query` over `scene` (which must hold the
    /// candidates).
    pub fn new(backend: &'a CpuBackend, scene: &'a CpuScene, rays: &'a [Ray], query: Query) -> Self {
        CpuClock { backend, scene, rays, part: part(rays), query, hits: vec![Hit::MISS; rays.len()] }
    }
}

impl SampleClock for CpuClock<'_> {
    fn seconds(&mut self, method: Method, portion: Portion) -> Result<f64, Error> {
        let opts = TraceOptions::new(method).query(self.query);
        let rays = match portion {
            Portion::Part => &self.part,
            Portion::Whole => self.rays,
        };
        Ok(self.backend.trace(self.scene, rays, &opts, &mut self.hits[..rays.len()])?.seconds)
    }
}

/// Chooses among [`CANDIDATES`] (those `scene` holds) for `rays` traced with `query`, timing a
/// [`sample`] of them on the CPU backend, after one untimed trace; the list walk of the winner's
/// tree is then judged on whole streams of the batch ([`streams::judge`]). The cost counted in
/// the choice is every trace's time, those included.
///
/// Fails with [`Error::NotPrepared`] when the scene holds none of the candidates, and
/// [`Error::InvalidParameter`] for an empty batch.
pub fn choose_on_cpu(backend: &CpuBackend, scene: &CpuScene, rays: &[Ray], query: Query) -> Result<Choice, Error> {
    choose_among(&CANDIDATES, backend, scene, rays, query)
}

/// As [`choose_on_cpu`], among `candidates` (those `scene` holds) instead of [`CANDIDATES`].
pub fn choose_among(
    candidates: &[Method],
    backend: &CpuBackend,
    scene: &CpuScene,
    rays: &[Ray],
    query: Query,
) -> Result<Choice, Error> {
    if rays.is_empty() {
        return Err(Error::InvalidParameter {
            name: "rays",
            why: "a method is chosen for a batch of at least one ray",
        });
    }
    let candidates: Vec<Method> = candidates.iter().copied().filter(|&m| scene.0.check_prepared(m).is_ok()).collect();
    if candidates.is_empty() {
        return Err(Error::NotPrepared { method: "auto", missing: "any of its candidate methods' structures" });
    }
    // A sample cannot judge the list walks (`streams.rs`): they are left out of it and judged
    // after it, unless nothing else is a candidate.
    let on_sample: Vec<Method> = candidates.iter().copied().filter(|&m| !walks_lists(m)).collect();
    let on_sample = if on_sample.is_empty() { candidates.clone() } else { on_sample };
    let sample = sample(rays);
    let mut clock = CpuClock::new(backend, scene, &sample, query);
    // One untimed trace starts the thread pool's workers (the first trace in a process pays for
    // that) so that the first candidate's first round is not judged by it.
    let warm = clock.seconds(on_sample[0], Portion::Part)?;
    let mut choice = choose(&on_sample, ROUNDS, &mut clock)?;
    choice.cost_seconds += warm;
    if let Some(verdict) = streams::judge(backend, scene, rays, query, choice.method, &candidates)? {
        choice.cost_seconds += verdict.cost_seconds();
        choice.method = verdict.method();
        choice.lists = Some(verdict);
    }
    Ok(choice)
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail_core::glam::Vec3;

    fn rays(n: usize) -> Vec<Ray> {
        (0..n).map(|i| Ray::new(Vec3::new(i as f32, 0.0, 0.0), Vec3::Z, 0.0, f32::INFINITY)).collect()
    }

    #[test]
    fn sample_sizes() {
        assert_eq!(sample_size(100), 100);
        assert_eq!(sample_size(10_000), MIN_SAMPLE);
        assert_eq!(sample_size(196_608), 1536);
        assert_eq!(sample_size(1_000_000) % (SAMPLE_RUNS * SAMPLE_RUN_UNIT), 0);
        assert_eq!(sample_size(100_000_000), MAX_SAMPLE);
    }

    #[test]
    fn a_sample_is_runs_of_consecutive_rays_from_each_share_of_the_batch() {
        let all = rays(196_608);
        let s = sample(&all);
        assert_eq!(s.len(), sample_size(all.len()));
        let index = |r: &Ray| r.origin().x as usize;
        let share = all.len() / SAMPLE_RUNS;
        for (k, run) in s.chunks(sample_size(all.len()).div_ceil(SAMPLE_RUNS)).enumerate() {
            assert!(run.windows(2).all(|w| index(&w[1]) == index(&w[0]) + 1), "run {k} is consecutive");
            assert_eq!(index(&run[0]) / share, k, "run {k} lies in share {k}");
        }
        // The first look's part: a quarter of each run, in whole packets.
        let p = part(&s);
        let run = sample_size(all.len()).div_ceil(SAMPLE_RUNS);
        assert_eq!(run % SAMPLE_RUN_UNIT, 0);
        assert_eq!(p.len(), SAMPLE_RUNS * (run / 4).next_multiple_of(SAMPLE_RUN_UNIT));
        assert!(p.chunks(SAMPLE_RUN_UNIT).all(|c| c.windows(2).all(|w| index(&w[1]) == index(&w[0]) + 1)));
        assert_eq!(p.iter().map(|r| index(r) / share).collect::<std::collections::BTreeSet<_>>().len(), SAMPLE_RUNS);
        assert!(part(&[]).is_empty());
        // A small batch is its own sample.
        assert_eq!(sample(&all[..300]).len(), 300);
        assert!(sample(&[]).is_empty());
    }
}
