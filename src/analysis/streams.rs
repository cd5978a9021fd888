//! How `auto` judges the ray-list walks: on whole streams of the batch, not on the sample.
//!
//! A ray-list walk ([`WideWalk::RayLists`]) fetches each node once for every ray of a stream
//! ([`STREAM_RAYS`] consecutive rays of the batch) that reaches it, so its speed rises with how
//! many of a stream's rays meet in a node, and the sample cannot show it: the sample is a 160th of
//! the batch in sixteen runs, traced as one short stream, with a few times fewer rays per node than
//! the batch's streams. On Sponza's diffuse rays in no order the sample's first look had
//! `bvh8-sah-lists` 2.5 times slower than the single-ray walk; over the batch it was 1.2-1.3 times
//! faster (`docs/notes/*-spatial-splits.md`, "auto").
//!
//! So the list walks are left out of the sample. After it, the list walk of the winner's tree is
//! timed against the winner on whole streams of the batch ([`check`]), where the batch is large
//! enough for that to be cheap; on a smaller batch that still fills [`MIN_STREAMS_PER_THREAD`]
//! streams on every thread, it is taken by rule where the winner walks single rays (the sample
//! found no coherence that packets profit from), as it was the faster on every such batch of the
//! notes' table. A closest-hit batch smaller still, of at least [`SMALL_CHECK_MIN_STREAMS_PER_THREAD`]
//! streams a thread, won by single rays, has the two timed on one whole stream a thread.

use raytrail_core::method::{Method, Query, WideMethod, WideWalk};
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::wide::STREAM_RAYS;
use raytrail_core::{Error, Hit, Ray};
use raytrail_cpu::{CpuBackend, CpuScene};

/// Whole streams per thread the check traces: two, so that one slow stream does not leave a
/// thread idle while the other finishes.
pub const CHECK_STREAMS_PER_THREAD: usize = 2;

/// The check runs on batches of at least this many times its own rays: its three traces then
/// cost about a fifth of one trace of the batch at the most, and a twentieth of a million-ray
/// batch on two threads.
pub const CHECK_SHARE: usize = 16;

/// Streams per thread a batch too small for the check must fill for the rule to take a list walk.
pub const MIN_STREAMS_PER_THREAD: usize = 16;

/// Streams per thread a closest-hit batch too small for the check and the rule must fill for the
/// small check: the sample's single-ray winner and the list walk timed on one whole stream a
/// thread (its three traces cost up to three eighths of one trace of such a batch). On batches of
/// 8-16 streams a thread whose sample single rays won, the list walk was the faster on the full
/// dragon's diffuse rays (1.15-1.23 from outside, 69,003 rays on two threads; 1.17-1.21 from
/// inside, 82,944) and the kitchen's from inside (1.07-1.09), tied on Sponza's from inside
/// (0.95-1.03) and lost on Sponza's from outside (0.89-0.91, 116,601), so it is timed there, not
/// taken by rule (`docs/notes/*-walk-experiments-and-auto-lists.md`). Any-hit batches are left
/// out: there the list walk lost on the kitchen's shuffled shadow rays from inside (0.86-0.88).
pub const SMALL_CHECK_MIN_STREAMS_PER_THREAD: usize = 8;

/// Why a list walk was taken instead of the sample's winner, or was not.
#[derive(Clone, Debug, PartialEq)]
pub enum ListsVerdict {
    /// Timed against the winner on whole streams of the batch.
    Timed(StreamCheck),
    /// Taken by rule: the winner, a single-ray walk, for a batch too small for the check.
    Rule {
        /// The sample's winner.
        winner: Method,
        /// Its tree's list walk, taken instead.
        lists: Method,
    },
}

/// What the check measured.
#[derive(Clone, Debug, PartialEq)]
pub struct StreamCheck {
    /// The sample's winner.
    pub winner: Method,
    /// The list walk of its tree.
    pub lists: Method,
    /// Rays the two were timed on: whole streams, [`CHECK_STREAMS_PER_THREAD`] per thread.
    pub rays: usize,
    /// Seconds of the winner's timed trace.
    pub winner_seconds: f64,
    /// Seconds of the list walk's timed trace (after an untimed one).
    pub lists_seconds: f64,
    /// Seconds of all the check's traces.
    pub cost_seconds: f64,
}

impl StreamCheck {
    /// Whether the list walk won: faster than the sample's winner. Without the margin that
    /// protects an earlier candidate on the sample (against samples that flatter larger
    /// structures): both walks read the same tree, and these rays are the batch's own streams.
    pub fn lists_won(&self) -> bool {
        self.lists_seconds < self.winner_seconds
    }
}

impl ListsVerdict {
    /// The method to trace with: the list walk where it won or the rule took it.
    pub fn method(&self) -> Method {
        match self {
            ListsVerdict::Timed(c) if c.lists_won() => c.lists,
            ListsVerdict::Timed(c) => c.winner,
            ListsVerdict::Rule { lists, .. } => *lists,
        }
    }

    /// Seconds it spent tracing.
    pub fn cost_seconds(&self) -> f64 {
        match self {
            ListsVerdict::Timed(c) => c.cost_seconds,
            ListsVerdict::Rule { .. } => 0.0,
        }
    }

    /// One clause for reports.
    pub fn summary(&self) -> String {
        match self {
            ListsVerdict::Timed(c) => format!(
                "then on {} rays in whole streams: {} {:.0}, {} {:.0}",
                c.rays,
                c.winner.name(),
                1e6 * c.winner_seconds,
                c.lists.name(),
                1e6 * c.lists_seconds
            ),
            ListsVerdict::Rule { winner, lists } => format!(
                "{} won the sample, and for a batch of at least {MIN_STREAMS_PER_THREAD} streams a thread {} is taken",
                winner.name(),
                lists.name()
            ),
        }
    }
}

/// Whether `method` walks ray lists.
pub fn walks_lists(method: Method) -> bool {
    method.wide().is_some_and(|m| m.walk() == WideWalk::RayLists)
}

/// Whether `method` walks single rays down a wide tree (the sample's winner the rule and the
/// small check give way to the list walk).
pub fn walks_single_rays(method: Method) -> bool {
    method.wide().is_some_and(|m| m.walk() == WideWalk::Stack)
}

/// Whether a batch of `rays` fills `streams` whole streams on each of `threads` threads.
fn fills(rays: usize, streams: usize, threads: usize) -> bool {
    rays >= streams * threads.max(1) * STREAM_RAYS
}

/// The ray-list walk of `method`'s wide tree (`None` for a method of no wide tree, or of a tree
/// no list walk reads).
pub fn lists_of(method: Method) -> Option<Method> {
    let wide = method.wide()?;
    WideMethod::new(wide.tree(), WideWalk::RayLists).ok().map(Method::Wide)
}

/// `count` whole streams of `rays` (each starting at a multiple of [`STREAM_RAYS`] from the
/// batch's start, as the backend cuts them), spread evenly over the batch; empty where the batch
/// holds fewer than `count` streams.
pub fn whole_streams(rays: &[Ray], count: usize) -> Vec<Ray> {
    let streams = rays.len() / STREAM_RAYS;
    if count == 0 || streams < count {
        return Vec::new();
    }
    let mut out = Vec::with_capacity(count * STREAM_RAYS);
    for k in 0..count {
        // The stream in the middle of the k-th of `count` equal shares of the batch's streams.
        let s = (2 * k + 1) * streams / (2 * count);
        out.extend_from_slice(&rays[s * STREAM_RAYS..(s + 1) * STREAM_RAYS]);
    }
    out
}

/// Times `winner` and `lists` on `per_thread` whole streams a thread of `rays` traced with
/// `query`: one untimed trace of the list walk (without it, its first trace on the check's few
/// streams ran a quarter slower than over the batch, and the check called a tie where the batch
/// had the list walk 1.3 times ahead), then one timed trace of each. `None` where the batch holds
/// fewer streams than that.
pub fn check(
    backend: &CpuBackend,
    scene: &CpuScene,
    rays: &[Ray],
    query: Query,
    (winner, lists): (Method, Method),
    per_thread: usize,
) -> Result<Option<StreamCheck>, Error> {
    let sample = whole_streams(rays, per_thread * backend.threads().max(1));
    if sample.is_empty() {
        return Ok(None);
    }
    let mut hits = vec![Hit::MISS; sample.len()];
    let mut time = |m: Method| -> Result<f64, Error> {
        Ok(backend.trace(scene, &sample, &TraceOptions::new(m).query(query), &mut hits)?.seconds)
    };
    let warm = time(lists)?;
    let (winner_seconds, lists_seconds) = (time(winner)?, time(lists)?);
    Ok(Some(StreamCheck {
        winner,
        lists,
        rays: sample.len(),
        winner_seconds,
        lists_seconds,
        cost_seconds: warm + winner_seconds + lists_seconds,
    }))
}

/// The list walk the rule takes instead of `winner`, the sample's choice for a batch of `rays`
/// traced on `threads` threads: that of its tree, where `winner` walks single rays, the batch
/// fills [`MIN_STREAMS_PER_THREAD`] streams per thread and the walk is among `candidates`.
pub fn lists_instead(winner: Method, rays: usize, threads: usize, candidates: &[Method]) -> Option<Method> {
    let taken = walks_single_rays(winner) && fills(rays, MIN_STREAMS_PER_THREAD, threads);
    lists_of(winner).filter(|l| taken && candidates.contains(l))
}

/// The verdict on the list walk of `winner`'s tree for `rays` (`None`: no list walk is a
/// candidate, or the batch is too small for the check and the rule does not take one).
pub fn judge(
    backend: &CpuBackend,
    scene: &CpuScene,
    rays: &[Ray],
    query: Query,
    winner: Method,
    candidates: &[Method],
) -> Result<Option<ListsVerdict>, Error> {
    let Some(lists) = lists_of(winner).filter(|l| candidates.contains(l) && !walks_lists(winner)) else {
        return Ok(None);
    };
    let threads = backend.threads().max(1);
    if fills(rays.len(), CHECK_SHARE * CHECK_STREAMS_PER_THREAD, threads) {
        return Ok(
            check(backend, scene, rays, query, (winner, lists), CHECK_STREAMS_PER_THREAD)?.map(ListsVerdict::Timed)
        );
    }
    if let Some(lists) = lists_instead(winner, rays.len(), threads, candidates) {
        return Ok(Some(ListsVerdict::Rule { winner, lists }));
    }
    if small_check(winner, rays.len(), query, threads) {
        return Ok(check(backend, scene, rays, query, (winner, lists), 1)?.map(ListsVerdict::Timed));
    }
    Ok(None)
}

/// Whether a batch of `rays` answering `query` on `threads` threads, too small for the check and
/// the rule, has `winner` timed against the list walk on one stream a thread: a closest-hit batch
/// of at least [`SMALL_CHECK_MIN_STREAMS_PER_THREAD`] streams a thread whose sample single rays
/// won.
pub fn small_check(winner: Method, rays: usize, query: Query, threads: usize) -> bool {
    walks_single_rays(winner) && query == Query::Closest && fills(rays, SMALL_CHECK_MIN_STREAMS_PER_THREAD, threads)
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail_core::glam::Vec3;
    use raytrail_core::method::KdMethod;

    const SINGLE: Method = Method::Wide(WideMethod::BVH8_SAH);
    const LISTS: Method = Method::Wide(WideMethod::BVH8_SAH_LISTS);
    const CANDIDATES: [Method; 2] = [SINGLE, LISTS];

    fn rays(n: usize) -> Vec<Ray> {
        (0..n).map(|i| Ray::new(Vec3::new(i as f32, 0.0, 0.0), Vec3::Z, 0.0, f32::INFINITY)).collect()
    }

    #[test]
    fn each_wide_tree_has_its_list_walk() {
        assert_eq!(lists_of(SINGLE), Some(LISTS));
        assert_eq!(lists_of(Method::Wide(WideMethod::BVH8_SAH_PACKET)), Some(LISTS));
        assert_eq!(lists_of(Method::Wide(WideMethod::BVH8_PACKET)), Some(Method::Wide(WideMethod::BVH8_LISTS)));
        assert_eq!(lists_of(Method::Kd(KdMethod::Stack)), None);
        assert!(walks_lists(LISTS) && !walks_lists(SINGLE));
    }

    #[test]
    fn whole_streams_start_where_the_backend_cuts_and_spread_over_the_batch() {
        let all = rays(40 * STREAM_RAYS + 17);
        let s = whole_streams(&all, 4);
        assert_eq!(s.len(), 4 * STREAM_RAYS);
        let starts: Vec<usize> = s.chunks(STREAM_RAYS).map(|c| c[0].origin().x as usize).collect();
        assert_eq!(starts, [5, 15, 25, 35].map(|k| k * STREAM_RAYS));
        for c in s.chunks(STREAM_RAYS) {
            assert!(c.windows(2).all(|w| w[1].origin().x == w[0].origin().x + 1.0));
        }
        assert!(whole_streams(&all[..3 * STREAM_RAYS], 4).is_empty());
        assert!(whole_streams(&all, 0).is_empty());
    }

    #[test]
    fn the_list_walk_must_be_faster_on_the_streams() {
        let c = |w, l| {
            let check = StreamCheck {
                winner: SINGLE,
                lists: LISTS,
                rays: 1,
                winner_seconds: w,
                lists_seconds: l,
                cost_seconds: 0.0,
            };
            ListsVerdict::Timed(check).method()
        };
        assert_eq!(c(1.0, 0.99), LISTS);
        assert_eq!(c(1.0, 1.0), SINGLE, "a tie keeps the sample's winner");
        assert_eq!(c(1.0, 1.2), SINGLE);
    }

    #[test]
    fn the_small_check_is_for_closest_hit_batches_won_by_single_rays() {
        let eight = SMALL_CHECK_MIN_STREAMS_PER_THREAD * 2 * STREAM_RAYS;
        assert!(small_check(SINGLE, eight, Query::Closest, 2));
        assert!(!small_check(SINGLE, eight - 1, Query::Closest, 2), "too few streams per thread");
        assert!(!small_check(SINGLE, eight, Query::Closest, 3), "the same batch on more threads");
        assert!(!small_check(SINGLE, eight, Query::Any, 2), "any-hit rays");
        assert!(!small_check(Method::Wide(WideMethod::BVH8_SAH_PACKET), eight, Query::Closest, 2), "packets won");
    }

    #[test]
    fn the_rule_takes_lists_for_large_batches_won_by_single_rays() {
        let full = MIN_STREAMS_PER_THREAD * 2 * STREAM_RAYS;
        assert_eq!(lists_instead(SINGLE, full, 2, &CANDIDATES), Some(LISTS));
        assert_eq!(lists_instead(SINGLE, full - 1, 2, &CANDIDATES), None, "too few streams per thread");
        assert_eq!(lists_instead(SINGLE, full, 4, &CANDIDATES), None, "the same batch on more threads");
        let packet = Method::Wide(WideMethod::BVH8_SAH_PACKET);
        assert_eq!(lists_instead(packet, full, 2, &[packet, LISTS]), None, "coherent rays keep their packets");
        assert_eq!(lists_instead(SINGLE, full, 2, &[SINGLE]), None, "not a candidate");
        assert_eq!(lists_instead(Method::Kd(KdMethod::Stack), full, 2, &CANDIDATES), None);
    }
}
