//! One ray's hit list while the walk finds its hits: kept in order of `(t, prim)`, merged at
//! equal `t` where asked, and cut to the limit, whose last distance then culls the walk.

use super::AllHitsOptions;
use crate::Hit;
use alloc::vec::Vec;

/// One ray's hits so far, at the end of a buffer the batch shares (`out[start..]`).
#[derive(Debug)]
pub struct HitList<'a> {
    out: &'a mut Vec<Hit>,
    start: usize,
    /// Hits to keep: the limit and one more, whose presence says the list is truncated.
    keep: usize,
    merge: bool,
    /// Hits beyond this distance cannot be among the kept ones: the ray's `tmax` until `keep`
    /// hits are held, then the distance of the last one (inclusive: an equal `t` with a lower
    /// primitive id still displaces it).
    cull: f32,
    /// Entries since the last compaction.
    fresh: usize,
}

impl<'a> HitList<'a> {
    /// An empty list appended to `out`, for a ray whose interval ends at `tmax`.
    pub fn new(out: &'a mut Vec<Hit>, options: &AllHitsOptions, tmax: f32) -> Self {
        let start = out.len();
        HitList {
            out,
            start,
            keep: options.max_hits.saturating_add(1),
            merge: options.merge_equal_t,
            cull: tmax,
            fresh: 0,
        }
    }

    /// The distance beyond which no hit can be kept (see the field).
    #[inline(always)]
    pub fn limit(&self) -> f32 {
        self.cull
    }

    /// Adds a hit found within `[tmin, limit]`.
    #[inline]
    pub fn offer(&mut self, hit: Hit) {
        self.out.push(hit);
        self.fresh += 1;
        // Compacting when the unsorted tail outgrows what is kept (at least 32 entries) sorts each
        // hit a bounded number of times, so a ray of many hits and a small limit stays linear.
        if self.fresh >= self.keep.max(32) {
            self.compact();
        }
    }

    /// Sorts by `(t, prim)`, merges equal `t` where asked and cuts to `keep`.
    fn compact(&mut self) {
        sort_and_merge(self.out, self.start, self.merge);
        if self.out.len() - self.start >= self.keep {
            self.out.truncate(self.start + self.keep);
            if let Some(last) = self.out.last() {
                self.cull = self.cull.min(last.t);
            }
        }
        self.fresh = 0;
    }

    /// The list in order, at most `max_hits` long; returns whether hits were cut off.
    pub fn finish(mut self) -> bool {
        self.compact();
        let max = self.keep - 1;
        let truncated = self.out.len() - self.start > max;
        if truncated {
            self.out.truncate(self.start + max);
        }
        truncated
    }
}

/// Sorts `out[start..]` by [`Hit::order`], keeps one of each triangle met twice at one `t` (in
/// two leaves of a tree with split references, bit for bit the same hit) and, with `merge`, only
/// the first (lowest id) of each run of equal `t` (`-0.0` equal to `0.0`, as the closest-hit rule
/// has it).
pub(super) fn sort_and_merge(out: &mut Vec<Hit>, start: usize, merge: bool) {
    out[start..].sort_unstable_by(Hit::order);
    let mut kept = start;
    for i in start..out.len() {
        let fresh = kept == start || {
            let last = &out[kept - 1];
            last.t != out[i].t || (!merge && last.prim != out[i].prim)
        };
        if fresh {
            out[kept] = out[i];
            kept += 1;
        }
    }
    out.truncate(kept);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(t: f32, prim: u32) -> Hit {
        Hit { t, prim, u: 0.0, v: 0.0 }
    }

    fn listed(hits: &[(f32, u32)], max_hits: usize, merge: bool) -> (Vec<(f32, u32)>, bool) {
        let mut out = alloc::vec![hit(-1.0, 99)];
        let options = AllHitsOptions { max_hits, merge_equal_t: merge };
        let mut list = HitList::new(&mut out, &options, f32::INFINITY);
        for &(t, p) in hits {
            list.offer(hit(t, p));
        }
        let truncated = list.finish();
        assert_eq!(out[0].prim, 99, "what was in the buffer before stays");
        (out[1..].iter().map(|h| (h.t, h.prim)).collect(), truncated)
    }

    #[test]
    fn lists_are_in_order_of_t_then_prim_cut_and_merged_as_asked() {
        let hits = [(3.0, 1), (1.0, 7), (2.0, 4), (1.0, 2), (5.0, 0)];
        let all = listed(&hits, usize::MAX, false);
        assert_eq!(all, (alloc::vec![(1.0, 2), (1.0, 7), (2.0, 4), (3.0, 1), (5.0, 0)], false));
        assert!(!listed(&hits, 5, false).1);
        assert_eq!(listed(&hits, 2, false), (alloc::vec![(1.0, 2), (1.0, 7)], true));
        assert_eq!(listed(&hits, usize::MAX, true).0, alloc::vec![(1.0, 2), (2.0, 4), (3.0, 1), (5.0, 0)]);
        assert_eq!(listed(&hits, 2, true), (alloc::vec![(1.0, 2), (2.0, 4)], true));
        assert_eq!(listed(&[], 0, false), (alloc::vec![], false));
        assert_eq!(listed(&hits, 0, false), (alloc::vec![], true));
        // A triangle met in two leaves (split references) is listed once, merged or not.
        let twice = [(2.0, 4), (1.0, 7), (2.0, 4), (2.0, 5)];
        assert_eq!(listed(&twice, usize::MAX, false).0, alloc::vec![(1.0, 7), (2.0, 4), (2.0, 5)]);
        assert_eq!(listed(&twice, 2, false), (alloc::vec![(1.0, 7), (2.0, 4)], true));
        assert_eq!(listed(&twice, usize::MAX, true).0, alloc::vec![(1.0, 7), (2.0, 4)]);
    }

    #[test]
    fn a_full_list_culls_at_its_last_kept_distance() {
        let mut out = Vec::new();
        let options = AllHitsOptions { max_hits: 3, merge_equal_t: false };
        let mut list = HitList::new(&mut out, &options, 100.0);
        for k in 0..40 {
            list.offer(hit(100.0 - k as f32, k));
        }
        // The 32nd offer compacted the list to the four nearest so far (three and one more: 69 to
        // 72), and the limit came down to the last of them; the eight offers since wait unsorted.
        assert_eq!(list.limit(), 72.0);
        assert!(list.finish());
        assert_eq!(out.iter().map(|h| h.t).collect::<Vec<_>>(), alloc::vec![61.0, 62.0, 63.0]);
    }
}
