//! [`TraceOrder::Sorted`] on the CPU: the batch's rays sorted by [`OriginOctantKey`] on the
//! backend's threads, traced in that order as any batch is, and their hits (and recorded
//! enumerations) written back to the places the caller gave the rays. The report's time covers
//! the sort and both copies.
//!
//! The whole batch is sorted at once: sorting windows of 16k-256k rays each (cheaper, in cache)
//! kept too little of the gain, since what pays is rays that start close together, and a window
//! holds few of those (`docs/notes/*-sorted-trace-order.md`, "Windows").

use crate::backend::{CpuBackend, CpuScene};
use rayon::prelude::*;
use raytrail_core::trace::{check_buffers, Report, Trace, TraceOptions};
use raytrail_core::trace_order::{OriginOctantKey, TraceOrder};
use raytrail_core::{Aabb, Error, Hit, Ray};
use std::sync::Mutex;
use std::time::Instant;

/// Rays per task of the passes over the batch (the box of the origins, the copies).
const PASS_RAYS: usize = 1 << 14;

/// Bits of the key a batch is sorted by: the octant's 3 and the top 12 of the origin's Morton
/// code, a `16^3` grid over the origins. Rays within a cell keep their order.
const BUCKET_BITS: u32 = 15;

/// The buffers of a sorted trace, kept by the backend from one batch to the next: allocated
/// afresh, the 54 bytes a ray of them cost a page fault every 76 rays, more than the sort itself
/// (`docs/notes/*-sorted-trace-order.md`, "What the sort costs").
#[derive(Debug, Default)]
struct SortBuffers {
    /// Each ray's bucket, by position.
    buckets: Vec<u16>,
    /// The positions of the rays in sorted order.
    order: Vec<u32>,
    /// The rays in sorted order.
    rays: Vec<Ray>,
    /// Their hits.
    hits: Vec<Hit>,
}

/// The backend's sort buffers; a trace that finds them held by another makes its own.
#[derive(Debug, Default)]
pub(crate) struct SortScratch(Mutex<SortBuffers>);

/// Traces `rays` in the order of their keys into `hits`, in the caller's order, in `backend`'s
/// sort buffers.
pub(crate) fn trace_sorted(
    backend: &CpuBackend,
    scene: &CpuScene,
    rays: &[Ray],
    opts: &TraceOptions,
    hits: &mut [Hit],
) -> Result<Report, Error> {
    check_buffers(rays, hits)?;
    let start = Instant::now();
    let mut fresh = SortBuffers::default();
    let mut held = backend.sort_buffers.0.try_lock();
    let buffers = match held.as_deref_mut() {
        Ok(b) => b,
        Err(_) => &mut fresh,
    };
    backend.install(|| sort(rays, buffers));
    let mut report = backend.trace(scene, &buffers.rays, &opts.order(TraceOrder::AsGiven), &mut buffers.hits)?;
    backend.install(|| scatter(&buffers.order, &buffers.hits, hits));
    if let Some(e) = report.enumerations.as_mut() {
        let mut back = vec![Vec::new(); e.len()];
        for (sorted, &given) in buffers.order.iter().enumerate() {
            back[given as usize] = core::mem::take(&mut e[sorted]);
        }
        *e = back;
    }
    report.seconds = start.elapsed().as_secs_f64();
    Ok(report)
}

/// Fills `b` for `rays`: the positions in the order of their buckets (a bucket's rays in the
/// order given), the rays in that order, and room for their hits. A counting sort: each task
/// keys and counts its part of the batch, then places its part's positions. One pass over the
/// `2^15` buckets writes positions (4 bytes) only, which stay in cache; sorting (bucket,
/// position) words by two radix passes instead cost a third more.
fn sort(rays: &[Ray], b: &mut SortBuffers) {
    let n = rays.len();
    let origins = rays
        .par_chunks(PASS_RAYS)
        .map(|c| c.iter().map(Ray::origin).filter(|o| o.is_finite()).fold(Aabb::EMPTY, Aabb::grow))
        .reduce(|| Aabb::EMPTY, Aabb::union);
    let key = OriginOctantKey::new(origins);
    b.buckets.resize(n, 0);
    b.order.resize(n, 0);
    b.rays.resize(n, Ray { origin: [0.0; 3], tmin: 0.0, dir: [0.0; 3], tmax: 0.0 });
    b.hits.resize(n, Hit::MISS);
    let part = n.div_ceil(rayon::current_num_threads() * 2).max(PASS_RAYS);
    let mut next: Vec<Vec<u32>> = b
        .buckets
        .par_chunks_mut(part)
        .zip(rays.par_chunks(part))
        .map(|(buckets, rays)| {
            let mut count = vec![0u32; 1 << BUCKET_BITS];
            for (bucket, r) in buckets.iter_mut().zip(rays) {
                *bucket = (key.key(r) >> (OriginOctantKey::BITS - BUCKET_BITS)) as u16;
                count[usize::from(*bucket)] += 1;
            }
            count
        })
        .collect();
    // Each part's first place per bucket: the bucket's start, after the earlier parts' rays in it.
    let mut at = 0u32;
    for bucket in 0..1 << BUCKET_BITS {
        for count in next.iter_mut() {
            (count[bucket], at) = (at, at + count[bucket]);
        }
    }
    let out = Shared(b.order.as_mut_ptr());
    b.buckets.par_chunks(part).zip(next.par_iter_mut()).enumerate().for_each(|(p, (buckets, next))| {
        for (i, &bucket) in buckets.iter().enumerate() {
            let place = &mut next[usize::from(bucket)];
            if (*place as usize) < n {
                // SAFETY: the places handed out over all parts and buckets are `0..n`, each once
                // (the starts above are the exclusive prefix sums of the counts), so no two
                // writes meet, and each is in bounds.
                unsafe { out.write(*place as usize, (p * part + i) as u32) };
            }
            *place += 1;
        }
    });
    b.rays.par_chunks_mut(PASS_RAYS).zip(b.order.par_chunks(PASS_RAYS)).for_each(|(out, order)| {
        for (o, &i) in out.iter_mut().zip(order) {
            *o = rays[i as usize];
        }
    });
}

/// A buffer written by several tasks at places no two share.
#[derive(Clone, Copy)]
struct Shared<T>(*mut T);
// SAFETY: the tasks write disjoint places only (see the writes).
unsafe impl<T> Send for Shared<T> {}
// SAFETY: as above.
unsafe impl<T> Sync for Shared<T> {}

impl<T> Shared<T> {
    /// Writes `value` at place `i`. (A method, so that closures take the whole wrapper, which is
    /// `Sync`, and not its raw pointer field, which is not.)
    ///
    /// # Safety
    /// `i` must be in bounds of the buffer, and no other write may meet it.
    #[inline(always)]
    unsafe fn write(&self, i: usize, value: T) {
        // SAFETY: the caller's promise.
        unsafe { *self.0.add(i) = value };
    }
}

/// `hits[order[k]] = sorted[k]` for every `k`, on the pool's threads.
fn scatter(order: &[u32], sorted: &[Hit], hits: &mut [Hit]) {
    let (out, n) = (Shared(hits.as_mut_ptr()), hits.len());
    order.par_chunks(PASS_RAYS).zip(sorted.par_chunks(PASS_RAYS)).for_each(|(order, sorted)| {
        for (&i, h) in order.iter().zip(sorted) {
            let i = i as usize;
            if i < n {
                // SAFETY: `order` is a permutation of the positions of `hits` (each once, from
                // `sort`), so no two writes meet, and `i` is in bounds.
                unsafe { out.write(i, *h) };
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail_conformance::scenes::sphereflake;
    use raytrail_core::bvh2::SahBuilder;
    use raytrail_core::method::{Method, WideMethod};
    use raytrail_core::prepared::PreparedScene;
    use raytrail_core::trace::Record;

    /// A shuffled batch traced sorted answers as traced as given, hit for hit and enumeration for
    /// enumeration, and the sort is a permutation.
    #[test]
    fn sorted_traces_answer_as_given_ones() {
        let scene = sphereflake(2);
        let bvh = SahBuilder::default().build(scene.triangles()).unwrap();
        let backend = CpuBackend::with_threads(2).unwrap();
        let prepared =
            backend.prepare(std::sync::Arc::new(PreparedScene::new(&scene, bvh, &Method::ALL).unwrap())).unwrap();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 4.0 - 2.0
        };
        let rays: Vec<Ray> = (0..40_000)
            .map(|_| Ray {
                origin: [next(), next(), next()],
                tmin: 0.0,
                dir: [next(), next(), next()],
                tmax: f32::INFINITY,
            })
            .collect();
        for method in [Method::Wide(WideMethod::BVH8_SAH), Method::Wide(WideMethod::BVH8_PACKET)] {
            let given = TraceOptions::new(method).record(Record::Enumerations);
            let (mut a, mut b) = (vec![Hit::MISS; rays.len()], vec![Hit::MISS; rays.len()]);
            let ra = backend.trace(&prepared, &rays, &given, &mut a).unwrap();
            let rb = backend.trace(&prepared, &rays, &given.order(TraceOrder::Sorted), &mut b).unwrap();
            assert_eq!(a, b, "{method}");
            assert!(a.iter().filter(|h| h.is_hit()).count() > 1000, "too few hits to compare");
            if method == Method::Wide(WideMethod::BVH8_SAH) {
                // Single rays' enumerations are their own, whatever the order.
                assert_eq!(ra.enumerations, rb.enumerations);
            }
        }
        let mut b = SortBuffers::default();
        sort(&rays, &mut b);
        let mut seen = b.order.clone();
        seen.sort_unstable();
        assert!(seen.iter().enumerate().all(|(i, &p)| p as usize == i), "not a permutation");
    }
}
