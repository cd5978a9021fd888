//! The SAH kd-tree builder: Havran & Bittner's surface area heuristic with "perfect splits"
//! (triangles clipped to the node's cell), as Horn et al. (2007, Sec. 4) build their trees, with
//! equal traversal and intersection costs by default.
//!
//! Construction runs top-down from an explicit work stack (no recursion). Each node carries
//! references `(triangle, bounds of the triangle clipped to the node's cell)`; the split plane is
//! chosen by the SAH over those clipped bounds (`sah`), and a triangle crossing the plane is
//! clipped again against each child's cell (`clip`), so references only shrink going down.
//!
//! Which side a triangle goes to (the rule the traversals rely on): with `m` the plane margin
//! ([`KdBuilder::plane_margin`], a few float epsilons of the scene's size), a triangle goes below a
//! plane at `s` when its clipped bounds start at or below `s + m`, above when they end at or above
//! `s - m`. So:
//! - a triangle touching a plane, by a vertex, an edge or lying in it, goes to both children (the
//!   closed half-boxes), and so does one passing within `m` of it: each leaf holds every triangle
//!   that meets its cell grown by `m`, so that rounding in a ray's plane crossings or in the
//!   triangle test (a few ulps of the distances, for rays starting in or near the scene) cannot
//!   make a traversal miss a triangle near a plane;
//! - candidate planes lie `2m` outside a triangle's clipped bounds, never on them, so that empty
//!   space is cut off cleanly (a wall lies on one side of a plane just beside it, the side the
//!   SAH prefers) instead of the wall landing on both sides of a plane through it.
//!
//! No triangle is dropped: every triangle meeting the root cell (the scene bounds) is kept,
//! degenerate (zero-area) ones included, although the watertight test never hits them; a
//! reference leaves a child only when clipping shows that the triangle misses the child's cell
//! (grown by the margin). A node becomes a leaf when it is empty, at the depth cap, when its cell
//! is flat in two axes, or when no split is cheaper than the leaf.

use crate::geometry::clip;
mod sah;

use super::{KdNode, KdTree};
use crate::geometry::Triangle;
use crate::{Aabb, Error};
use alloc::vec::Vec;
use sah::{Split, SplitFinder};

/// Settings of the SAH kd-tree builder.
///
/// Cost model (Wald & Havran 2006): a leaf of `N` triangles costs `intersection_cost * N`; a
/// split costs `traversal_cost + intersection_cost * (A_below N_below + A_above N_above) / A`,
/// multiplied by `empty_bonus` when one side gets no triangle. A node is split only when the
/// cheapest split costs less than the leaf.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdConfig {
    /// Cost of one traversal step (default 1).
    pub traversal_cost: f32,
    /// Cost of one ray/triangle test (default 1: equal to a traversal step, Horn et al.'s setting).
    pub intersection_cost: f32,
    /// Factor applied to the cost of a split that leaves one side empty: the default 0.8 is Wald
    /// & Havran's 20% bonus for cutting off empty space; 1 disables it.
    pub empty_bonus: f32,
    /// Depth cap; nodes at the cap become leaves holding whatever reaches them. 0 (the default)
    /// means automatic: `8 + 1.3 log2(N)` for `N` triangles, rounded down. Never above
    /// [`Self::MAX_DEPTH`].
    pub max_depth: u32,
    /// Bins per axis of the binned search in nodes of more than 32 references (default 32; at
    /// least 2, at most 1024). Smaller nodes are searched exactly.
    pub bins: usize,
}

impl Default for KdConfig {
    fn default() -> Self {
        Self { traversal_cost: 1.0, intersection_cost: 1.0, empty_bonus: 0.8, max_depth: 0, bins: 32 }
    }
}

impl KdConfig {
    /// Deepest depth cap: keys of depth-63 nodes fit 64 bits (root key 1).
    pub const MAX_DEPTH: u32 = 63;

    /// The depth cap for `triangle_count` triangles: `max_depth`, or `8 + 1.3 log2(N)` rounded
    /// down when it is 0, at most [`Self::MAX_DEPTH`]. Integer arithmetic (`no_std` has no float
    /// `log2`): `log2(N)` to 10 fractional bits.
    pub fn depth_cap(&self, triangle_count: usize) -> u32 {
        if self.max_depth > 0 {
            return self.max_depth.min(Self::MAX_DEPTH);
        }
        let depth = 8 + 13 * log2_fixed10(triangle_count.max(1) as u64) / (10 << 10);
        (depth as u32).min(Self::MAX_DEPTH)
    }
}

/// `log2(n)` in units of `2^-10`, rounded down (for `n >= 1`): the bit length gives the integer
/// part; squaring the mantissa (in [1, 2), 32 fractional bits) yields one fractional bit a step.
fn log2_fixed10(n: u64) -> u64 {
    let k = 63 - n.leading_zeros() as u64;
    let mut m = ((n as u128) << 32 >> k) as u64;
    let mut log2 = k << 10;
    for bit in (0..10).rev() {
        m = ((m as u128 * m as u128) >> 32) as u64;
        if m >= 2 << 32 {
            m >>= 1;
            log2 |= 1 << bit;
        }
    }
    log2
}

/// The SAH kd-tree builder (see the module documentation for the rules).
#[derive(Clone, Copy, Debug, Default)]
pub struct KdBuilder {
    /// Settings.
    pub config: KdConfig,
}

/// A triangle's reference in a node: its index and its bounds clipped to the node's cell.
#[derive(Clone, Copy, Debug)]
struct Ref {
    bounds: Aabb,
    prim: u32,
}

/// A node waiting to be built: its references are `refs[start..end]`, always the top of the
/// reference stack when the node is popped.
struct Work {
    node: usize,
    start: usize,
    end: usize,
    depth: u32,
    cell: Aabb,
    /// The references are those of the last searched node, unchanged: the other side of its
    /// split was empty.
    same_refs: bool,
}

impl KdBuilder {
    /// The margin of the side rule for a scene with these bounds: `f32::EPSILON` times the larger
    /// of 32 times the scene's largest extent and 4 times its largest coordinate magnitude.
    ///
    /// Rounding in a ray's plane crossing `t` and in the triangle test's `t` is a few epsilons of
    /// the distances from the ray's origin, which are about the scene's size for rays starting
    /// in or near it; the second term keeps the margin at several ulps of the coordinates (a
    /// scene far from the origin), so candidate planes `2m` from a bound are distinct floats.
    pub fn plane_margin(bounds: &Aabb) -> f32 {
        let extent = bounds.extent().max_element();
        let scale = bounds.max_abs();
        f32::EPSILON * (32.0 * extent).max(4.0 * scale)
    }

    /// A builder with the given settings.
    pub fn new(config: KdConfig) -> Self {
        Self { config }
    }

    /// Builds a kd-tree over `triangles` (primitive id = index) whose box is the scene bounds.
    ///
    /// Errors: [`Error::EmptyScene`] without triangles, [`Error::NonFiniteVertex`] (vertex
    /// `3 * triangle + corner`) for a NaN or infinite coordinate, [`Error::TreeTooLarge`] when
    /// nodes or references outgrow the 30-bit addresses of [`KdNode`].
    pub fn build(&self, triangles: &[Triangle]) -> Result<KdTree, Error> {
        if triangles.is_empty() {
            return Err(Error::EmptyScene);
        }
        if triangles.len() >= KdNode::LIMIT as usize {
            return Err(Error::TreeTooLarge { what: "kd-tree triangles", size: triangles.len() });
        }
        let mut scene = Aabb::EMPTY;
        let mut tri_bounds = Vec::with_capacity(triangles.len());
        for (i, t) in triangles.iter().enumerate() {
            if let Some(corner) = t.v.iter().position(|v| !v.is_finite()) {
                return Err(Error::NonFiniteVertex { vertex: 3 * i + corner });
            }
            let b = t.bounds();
            scene = scene.union(b);
            tri_bounds.push(b);
        }
        let margin = Self::plane_margin(&scene);
        let depth_cap = self.config.depth_cap(triangles.len());
        let mut finder = SplitFinder::new(&self.config, margin);

        // References of the nodes on the work stack; the root's are the whole triangles.
        let mut refs: Vec<Ref> = Vec::with_capacity(2 * triangles.len());
        refs.extend(tri_bounds.iter().enumerate().map(|(i, &bounds)| Ref { bounds, prim: i as u32 }));
        let mut below_refs: Vec<Ref> = Vec::new();
        let mut nodes: Vec<KdNode> = Vec::with_capacity(2 * triangles.len());
        nodes.push(KdNode::leaf(0, 0));
        let mut prims: Vec<u32> = Vec::with_capacity(2 * triangles.len());
        let mut todo =
            alloc::vec![Work { node: 0, start: 0, end: refs.len(), depth: 0, cell: scene, same_refs: false }];

        while let Some(w) = todo.pop() {
            debug_assert_eq!(refs.len(), w.end, "a popped node's references are on top");
            refs.truncate(w.end);
            let split = if w.depth < depth_cap { finder.find(&refs[w.start..], &w.cell, w.same_refs) } else { None };
            let Some(Split { axis, pos, exact_counts }) = split else {
                let first = prims.len();
                prims.extend(refs[w.start..].iter().map(|r| r.prim));
                prims[first..].sort_unstable();
                if prims.len() >= KdNode::LIMIT as usize {
                    return Err(Error::TreeTooLarge { what: "kd-tree references", size: prims.len() });
                }
                nodes[w.node] = KdNode::leaf(first as u32, (prims.len() - first) as u32);
                refs.truncate(w.start);
                continue;
            };
            let below = nodes.len();
            if below + 2 >= KdNode::LIMIT as usize {
                return Err(Error::TreeTooLarge { what: "kd-tree nodes", size: below + 2 });
            }
            nodes[w.node] = KdNode::inner(axis, pos, below as u32);
            nodes.push(KdNode::leaf(0, 0));
            nodes.push(KdNode::leaf(0, 0));

            let (mut below_cell, mut above_cell) = (w.cell, w.cell);
            below_cell.max[axis] = pos;
            above_cell.min[axis] = pos;
            let kept = match exact_counts {
                // Empty space cut off: every reference goes to the other side unclipped (one
                // reaching the plane's margin band would go to both), so they stay where they
                // are; the empty child gets an empty range at the right end.
                Some((0, _)) => w.end,
                Some((_, 0)) => w.start,
                _ => partition(
                    &mut refs,
                    &mut below_refs,
                    w.start..w.end,
                    Plane { axis, pos, margin },
                    (triangles, &tri_bounds),
                    (&w.cell, &below_cell, &above_cell),
                ),
            };
            let depth = w.depth + 1;
            let (above_count, below_count) = (kept - w.start, refs.len() - kept);
            let count = w.end - w.start;
            if let Some((b, a)) = exact_counts {
                // Clipping may only drop a reference from a side the count included.
                debug_assert!(below_count <= b as usize && above_count <= a as usize);
            }
            // The child below is built first: its references are on top.
            todo.push(Work {
                node: below + 1,
                start: w.start,
                end: kept,
                depth,
                cell: above_cell,
                same_refs: below_count == 0 && above_count == count,
            });
            todo.push(Work {
                node: below,
                start: kept,
                end: refs.len(),
                depth,
                cell: below_cell,
                same_refs: above_count == 0 && below_count == count,
            });
        }
        KdTree::from_parts(nodes, prims, scene, triangles.len())
    }
}

/// A split plane and the side rule's margin.
#[derive(Clone, Copy)]
struct Plane {
    axis: usize,
    pos: f32,
    margin: f32,
}

/// Distributes the references `refs[range]` of a node split at `plane`: those going above are
/// compacted in place from `range.start`, those going below follow them (gathered in `below_refs`
/// on the way; a reference yields at most one of each, never ahead of the reader). A reference
/// crossing the plane's margin band is clipped to each child's cell grown by the margin. Returns
/// where the references going below start; `refs` then ends with them.
fn partition(
    refs: &mut Vec<Ref>,
    below_refs: &mut Vec<Ref>,
    range: core::ops::Range<usize>,
    plane: Plane,
    (triangles, tri_bounds): (&[Triangle], &[Aabb]),
    (cell, below_cell, above_cell): (&Aabb, &Aabb, &Aabb),
) -> usize {
    let Plane { axis, pos, margin } = plane;
    // Clipping is against the cells grown by the margin: the side rule's regions.
    let grow = |c: &Aabb| Aabb { min: c.min - margin, max: c.max + margin };
    let (below_clip, above_clip, parent_clip) = (grow(below_cell), grow(above_cell), grow(cell));
    below_refs.clear();
    let mut kept = range.start;
    for i in range {
        let r = refs[i];
        let (lo, hi) = (r.bounds.min[axis], r.bounds.max[axis]);
        let t = &triangles[r.prim as usize];
        let tb = &tri_bounds[r.prim as usize];
        let clip_below = lo <= pos + margin && hi > pos + margin;
        let clip_above = hi >= pos - margin && lo < pos - margin;
        let (mut to_below, mut to_above) = match (clip_below, clip_above) {
            // Crossing the whole margin band: clip once to the parent, then per side.
            (true, true) => {
                let (b, a) = clip::split_clipped_bounds(t, tb, &parent_clip, axis, pos + margin, pos - margin);
                (b.map(|c| shrink(r.bounds, c)), a.map(|c| shrink(r.bounds, c)))
            }
            (true, false) => (
                clip::clipped_bounds(t, tb, &below_clip).map(|c| shrink(r.bounds, c)),
                (hi >= pos - margin).then_some(r.bounds),
            ),
            (false, true) => (
                (lo <= pos + margin).then_some(r.bounds),
                clip::clipped_bounds(t, tb, &above_clip).map(|c| shrink(r.bounds, c)),
            ),
            (false, false) => ((lo <= pos + margin).then_some(r.bounds), (hi >= pos - margin).then_some(r.bounds)),
        };
        if to_below.is_none() && to_above.is_none() {
            // The triangle meets the parent's region, so it meets one child's; rounding said
            // otherwise: keep it on both sides.
            to_below = Some(shrink(r.bounds, below_clip));
            to_above = Some(shrink(r.bounds, above_clip));
        }
        if let Some(bounds) = to_below {
            below_refs.push(Ref { bounds, prim: r.prim });
        }
        if let Some(bounds) = to_above {
            refs[kept] = Ref { bounds, prim: r.prim };
            kept += 1;
        }
    }
    refs.truncate(kept);
    refs.extend_from_slice(below_refs);
    kept
}

/// `a` cut to `b` (both hold the true clipped triangle, so their overlap does too); `b` alone where
/// rounding leaves no overlap.
fn shrink(a: Aabb, b: Aabb) -> Aabb {
    let min = a.min.max(b.min);
    let max = a.max.min(b.max);
    if min.cmple(max).all() {
        Aabb { min, max }
    } else {
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn log2_to_ten_fractional_bits() {
        assert_eq!(log2_fixed10(1), 0);
        assert_eq!(log2_fixed10(2), 1024);
        assert_eq!(log2_fixed10(1 << 40), 40 << 10);
        assert_eq!(log2_fixed10(3), 1623); // 1.58496 * 1024 = 1623.0
        assert_eq!(log2_fixed10(1000), 10204); // 9.96578 * 1024 = 10204.9
        assert_eq!(log2_fixed10(u64::MAX), (64 << 10) - 1);
    }

    #[test]
    fn automatic_depth_follows_8_plus_1_3_log2_n() {
        let cfg = KdConfig::default();
        assert_eq!(cfg.depth_cap(1), 8);
        assert_eq!(cfg.depth_cap(1024), 21); // 8 + 13
        assert_eq!(cfg.depth_cap(6_320), 24); // 24.41
        assert_eq!(cfg.depth_cap(69_666), 28); // 28.91
        assert_eq!(cfg.depth_cap(871_414), 33); // log2 = 19.733: 33.65
        assert_eq!(cfg.depth_cap(usize::MAX), KdConfig::MAX_DEPTH);
        assert_eq!(KdConfig { max_depth: 100, ..cfg }.depth_cap(10), KdConfig::MAX_DEPTH);
        assert_eq!(KdConfig { max_depth: 5, ..cfg }.depth_cap(10), 5);
    }

    #[test]
    fn errors() {
        assert_eq!(KdBuilder::default().build(&[]).unwrap_err(), Error::EmptyScene);
        let t = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::new(0.0, f32::NAN, 0.0));
        assert_eq!(KdBuilder::default().build(&[t]).unwrap_err(), Error::NonFiniteVertex { vertex: 2 });
    }
}
