//! Choosing a node's split plane by the surface area heuristic (SAH).
//!
//! Cost of splitting a cell of area `A` at a plane: `C_t + C_i (A_l N_l + A_r N_r) / A`, times the
//! empty factor when one side gets no reference (Wald & Havran 2006); the cost of a leaf: `C_i N`.
//! `N_l` and `N_r` count the references each side gets under the builder's side rule (see
//! [`super`]): a reference goes below when its clipped bounds start at most `margin` above the
//! plane, above when they end at most `margin` below it.
//!
//! Two searches, both over the clipped bounds of the references:
//! - small nodes (at most [`EXACT_MAX`] references): exact, with candidate planes just outside
//!   every bound (`2 margin` below each start, above each end), each counted over all references;
//! - larger nodes: per-axis bins of bound starts and ends (Popov et al. 2006), with candidates at
//!   the bin boundaries and just outside the extreme bound in each bin, so that empty space is
//!   still cut off tightly.
//!
//! After a split that cuts off empty space, the child kept holds the very same references; an
//! exact search then re-costs the parent's candidates instead of counting again.

use super::{KdConfig, Ref};
use crate::Aabb;
use alloc::vec::Vec;

/// Nodes with at most this many references get the exact search; larger ones are binned.
const EXACT_MAX: usize = 32;

/// A chosen split: the plane `p[axis] = pos`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Split {
    pub axis: usize,
    pub pos: f32,
    /// References going below and above, when counted exactly (not binned): the builder's side
    /// rule gives these very counts.
    pub exact_counts: Option<(u32, u32)>,
}

/// The SAH search with its reusable buffers (no allocation per node).
pub(super) struct SplitFinder {
    traversal: f64,
    intersection: f64,
    empty_factor: f64,
    margin: f32,
    bins: usize,
    count_lo: Vec<u32>,
    count_hi: Vec<u32>,
    lowest: Vec<f32>,
    highest: Vec<f32>,
    /// Candidates of the last exact search, with their counts, for its references.
    cache: Vec<Candidate>,
    /// How many references the cache was made for (`usize::MAX`: none).
    cache_refs: usize,
}

/// A candidate plane of an exact search and its reference counts.
#[derive(Clone, Copy)]
struct Candidate {
    pos: f32,
    axis: u32,
    below: u32,
    above: u32,
}

/// One axis of the cell and the constants of the split cost on it (in `f64`, so that areas
/// neither overflow nor underflow).
struct AxisGeometry {
    axis: usize,
    lo: f32,
    hi: f32,
    /// Cost of a split at `p` with `nb` references below and `na` above:
    /// `C_t + per_ref (nb + na) + per_ref_and_length ((p - lo) nb + (hi - p) na)`, from the child
    /// areas `cross + (p - lo) perimeter` and `cross + (hi - p) perimeter` relative to the cell's,
    /// where `cross` is the cell's section across the axis and `perimeter` the sum of the two
    /// other extents.
    per_ref: f64,
    per_ref_and_length: f64,
}

/// Best candidate so far.
struct Best {
    cost: f64,
    split: Option<Split>,
}

impl SplitFinder {
    /// A search with `cfg`'s costs and bins and the side rule's `margin`.
    pub(super) fn new(cfg: &KdConfig, margin: f32) -> Self {
        let bins = cfg.bins.clamp(2, 1024);
        Self {
            traversal: cfg.traversal_cost as f64,
            intersection: cfg.intersection_cost as f64,
            empty_factor: cfg.empty_bonus as f64,
            margin,
            bins,
            count_lo: alloc::vec![0; 3 * bins],
            count_hi: alloc::vec![0; 3 * bins],
            lowest: alloc::vec![0.0; 3 * bins],
            highest: alloc::vec![0.0; 3 * bins],
            cache: Vec::with_capacity(6 * EXACT_MAX),
            cache_refs: usize::MAX,
        }
    }

    /// The cheapest split of the references `refs` of `cell`, if it is cheaper than a leaf.
    ///
    /// `same_refs`: `refs` are exactly (same bounds, same order) those of the previous call with
    /// references, whose cell held this one: the child kept after cutting off empty space. Its
    /// candidates and their counts are then unchanged and only re-costed in the smaller cell,
    /// which gives the same answer as a fresh search.
    pub(super) fn find(&mut self, refs: &[Ref], cell: &Aabb, same_refs: bool) -> Option<Split> {
        let n = refs.len();
        let e = [0, 1, 2].map(|a| cell.max[a] as f64 - cell.min[a] as f64);
        let area = e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
        // A cell flat in two axes (a segment or a point) holds only degenerate triangles.
        if n == 0 || area <= 0.0 {
            return None;
        }
        let mut best = Best { cost: self.intersection * n as f64, split: None };
        let mut axes = [None, None, None];
        for (a, slot) in axes.iter_mut().enumerate() {
            // No plane fits strictly inside a flat axis.
            if e[a] > 0.0 {
                let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                let relative = self.intersection / area;
                *slot = Some(AxisGeometry {
                    axis: a,
                    lo: cell.min[a],
                    hi: cell.max[a],
                    per_ref: e[b] * e[c] * relative,
                    per_ref_and_length: (e[b] + e[c]) * relative,
                });
            }
        }
        if same_refs && self.cache_refs == n {
            for c in &self.cache {
                if let Some(g) = &axes[c.axis as usize] {
                    self.consider(&mut best, g, c.pos, c.below, c.above, true);
                }
            }
            return best.split;
        }
        self.cache.clear();
        self.cache_refs = if n <= EXACT_MAX { n } else { usize::MAX };
        if n <= EXACT_MAX {
            for g in axes.iter().flatten() {
                self.exact(refs, g, &mut best);
            }
        } else {
            self.binned(refs, &axes, &mut best);
        }
        best.split
    }

    /// Takes the plane `pos` on `g`'s axis with `below` and `above` references (`exact`: counted
    /// exactly) if it beats `best`. Planes outside the open cell are ignored.
    #[inline]
    fn consider(&self, best: &mut Best, g: &AxisGeometry, pos: f32, below: u32, above: u32, exact: bool) {
        if !(pos > g.lo && pos < g.hi) {
            return;
        }
        let (p, nb, na) = (pos as f64, below as f64, above as f64);
        let length_below = p - g.lo as f64;
        let length_above = g.hi as f64 - p;
        let cost =
            self.traversal + g.per_ref * (nb + na) + g.per_ref_and_length * (length_below * nb + length_above * na);
        let cost = if below == 0 || above == 0 { cost * self.empty_factor } else { cost };
        if cost < best.cost {
            // `+ 0.0` turns `-0.0` into `+0.0`: one plane, one representation.
            let exact_counts = exact.then_some((below, above));
            *best = Best { cost, split: Some(Split { axis: g.axis, pos: pos + 0.0, exact_counts }) };
        }
    }

    /// Exact search on one axis of a node of at most [`EXACT_MAX`] references: candidates `2m`
    /// below every start and above every end, each counted over all references.
    fn exact(&mut self, refs: &[Ref], g: &AxisGeometry, best: &mut Best) {
        let a = g.axis;
        // Padding that never counts: starts above and ends below every plane. The counted length
        // is a multiple of 4 known only at run time, so the counting loop is vectorized rather
        // than unrolled.
        let mut starts = [f32::INFINITY; EXACT_MAX];
        let mut ends = [f32::NEG_INFINITY; EXACT_MAX];
        for (i, r) in refs.iter().enumerate() {
            starts[i] = r.bounds.min[a];
            ends[i] = r.bounds.max[a];
        }
        let padded = refs.len().next_multiple_of(4);
        let (counted_starts, counted_ends) = (&starts[..padded], &ends[..padded]);
        let (m, gap) = (self.margin, 2.0 * self.margin);
        for i in 0..refs.len() {
            for pos in [starts[i] - gap, ends[i] + gap] {
                // Bounds clipped at the cell's faces give planes outside it: skip those first.
                if !(pos > g.lo && pos < g.hi) {
                    continue;
                }
                let (below, above) = count_sides(counted_starts, counted_ends, pos + m, pos - m);
                self.cache.push(Candidate { pos, axis: a as u32, below, above });
                self.consider(best, g, pos, below, above, true);
            }
        }
    }

    /// Binned search on all axes at once (one pass over the references). The bins hold the bounds
    /// grown by the margin, under which the side rule is the closed one: below when the grown
    /// start is at most the plane, above when the grown end is at least it. Counts are estimates,
    /// off only by references whose grown bounds share the candidate's bin; the partition is
    /// exact either way.
    fn binned(&mut self, refs: &[Ref], axes: &[Option<AxisGeometry>; 3], best: &mut Best) {
        let bins = self.bins;
        let n = refs.len();
        let m = self.margin;
        self.count_lo.fill(0);
        self.count_hi.fill(0);
        self.lowest.fill(f32::INFINITY);
        self.highest.fill(f32::NEG_INFINITY);
        // Bin scale per axis; 0 for a flat axis, which then fills bin 0 and is never swept.
        let scale =
            axes.each_ref().map(|g| g.as_ref().map_or(0.0, |g| (bins as f64 / (g.hi as f64 - g.lo as f64)) as f32));
        let lo = axes.each_ref().map(|g| g.as_ref().map_or(0.0, |g| g.lo));
        let top = (bins - 1) as f32;
        let bin = |v: f32, a: usize| {
            let x = (v - lo[a]) * scale[a];
            (if x < top { x } else { top }) as usize
        };
        let (count_lo, count_hi) = (&mut self.count_lo[..3 * bins], &mut self.count_hi[..3 * bins]);
        let (lowest, highest) = (&mut self.lowest[..3 * bins], &mut self.highest[..3 * bins]);
        for r in refs {
            let (min, max) = (r.bounds.min.to_array(), r.bounds.max.to_array());
            for a in 0..3 {
                let (s, e) = (min[a] - m, max[a] + m);
                let (i, j) = (a * bins + bin(s, a), a * bins + bin(e, a));
                // Wrapping: no overflow is possible, and checks would slow builds with debug
                // assertions.
                count_lo[i] = count_lo[i].wrapping_add(1);
                count_hi[j] = count_hi[j].wrapping_add(1);
                lowest[i] = lowest[i].min(s);
                highest[j] = highest[j].max(e);
            }
        }
        for g in axes.iter().flatten() {
            let base = g.axis * bins;
            let width = (g.hi as f64 - g.lo as f64) / bins as f64;
            // Grown starts and ends in earlier bins.
            let (mut starts_before, mut ends_before) = (0usize, 0usize);
            for i in 0..bins {
                let (lo_count, hi_count) = (self.count_lo[base + i] as usize, self.count_hi[base + i] as usize);
                if i > 0 {
                    let pos = (g.lo as f64 + width * i as f64) as f32;
                    self.consider(best, g, pos, starts_before as u32, (n - ends_before) as u32, false);
                }
                if lo_count > 0 {
                    // A margin below the lowest grown start in this bin (`2m` below the bound),
                    // so that reference goes above: empty space is cut off tightly.
                    let pos = self.lowest[base + i] - m;
                    self.consider(best, g, pos, starts_before as u32, (n - ends_before) as u32, false);
                }
                if hi_count > 0 {
                    // A margin above the highest grown end in this bin.
                    let pos = self.highest[base + i] + m;
                    self.consider(
                        best,
                        g,
                        pos,
                        (starts_before + lo_count) as u32,
                        (n - ends_before - hi_count) as u32,
                        false,
                    );
                }
                starts_before += lo_count;
                ends_before += hi_count;
            }
        }
    }
}

/// How many `starts` are at most `lo` and how many `ends` at least `hi`.
#[inline(always)]
fn count_sides(starts: &[f32], ends: &[f32], lo: f32, hi: f32) -> (u32, u32) {
    let mut below = 0u32;
    let mut above = 0u32;
    // Wrapping adds (no overflow is possible): an overflow check would stop vectorization in
    // builds with debug assertions.
    for (&s, &e) in starts.iter().zip(ends) {
        below = below.wrapping_add((s <= lo) as u32);
        above = above.wrapping_add((e >= hi) as u32);
    }
    (below, above)
}
