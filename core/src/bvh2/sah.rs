use super::tree::{Bvh2, Bvh2Node, NodeKind};
use crate::geometry::Triangle;
use crate::{Aabb, Error};
use alloc::vec::Vec;
use glam::Vec3;

/// Settings of the binned SAH builder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SahConfig {
    /// Bins per axis.
    pub bins: usize,
    /// Cost of one node traversal step, relative to `intersection_cost`.
    pub traversal_cost: f32,
    /// Cost of one leaf test: of `leaf_block` triangles at once.
    pub intersection_cost: f32,
    /// Triangles a leaf test takes at once: a leaf of `n` triangles costs `ceil(n / leaf_block)`
    /// tests. 4 by default, as the wide BVHs and the stream method test leaves four triangles at
    /// a time (SIMD lanes), so a leaf of one triangle costs what a leaf of four does; 1 counts
    /// every triangle (the textbook model).
    pub leaf_block: u32,
    /// Leaves larger than this are split even when the SAH prefers a leaf.
    pub max_leaf_size: u32,
    /// Depth cap (at most 63, so keys fit in 64 bits); nodes at the cap become leaves.
    pub max_depth: u32,
}

impl Default for SahConfig {
    fn default() -> Self {
        // Per triangle, with both costs 1, leaves held 2.25 triangles on Sponza and every block
        // of four carried empty lanes; costed per block, bvh8 traced the dragon's camera and
        // diffuse rays 1.35-1.48 times as fast
        // (`docs/notes/*-benchmarks-leaf-cost-and-auto-sample.md`, "Leaves costed per block of four").
        Self { bins: 16, traversal_cost: 1.0, intersection_cost: 1.0, leaf_block: 4, max_leaf_size: 8, max_depth: 63 }
    }
}

impl SahConfig {
    /// The settings a build uses: depth at most 63, at least 2 bins, blocks of at least 1.
    pub(super) fn normalized(self) -> SahConfig {
        SahConfig {
            max_depth: self.max_depth.min(63),
            bins: self.bins.max(2),
            leaf_block: self.leaf_block.max(1),
            ..self
        }
    }

    /// Leaf tests a leaf of `n` triangles takes: `ceil(n / leaf_block)` (`leaf_block` at least 1).
    #[inline]
    pub fn leaf_tests(&self, n: u32) -> f32 {
        n.div_ceil(self.leaf_block.max(1)) as f32
    }
}

/// A binned SAH builder (Wald 2007): centroids binned along each axis, the split with the least
/// surface-area cost taken, a median split where binning cannot separate the primitives.
#[derive(Clone, Copy, Debug, Default)]
pub struct SahBuilder {
    /// Settings.
    pub config: SahConfig,
}

struct Work {
    slot: usize,
    start: usize,
    end: usize,
    depth: u32,
}

#[derive(Clone, Copy)]
pub(super) struct Bin {
    bounds: Aabb,
    count: u32,
}

impl Bin {
    /// A bin holding nothing.
    pub(super) const EMPTY: Bin = Bin { bounds: Aabb::EMPTY, count: 0 };
}

impl SahBuilder {
    /// A builder with the given settings.
    pub fn new(config: SahConfig) -> Self {
        Self { config }
    }

    /// Builds the canonical tree over `triangles` (primitive id = index).
    pub fn build(&self, triangles: &[Triangle]) -> Result<Bvh2, Error> {
        let bounds: Vec<Aabb> = triangles.iter().map(Triangle::bounds).collect();
        self.build_boxes(&bounds)
    }

    /// Builds the canonical tree over primitives known by their boxes `bounds` (primitive id =
    /// index): the tree [`SahBuilder::build`] makes of triangles with these boxes. The top level
    /// of an instanced scene is built over its instances' world boxes this way.
    pub fn build_boxes(&self, bounds: &[Aabb]) -> Result<Bvh2, Error> {
        if bounds.is_empty() {
            return Err(Error::EmptyScene);
        }
        let cfg = self.config.normalized();
        let centroids: Vec<Vec3> = bounds.iter().map(Aabb::center).collect();
        let mut prims: Vec<u32> = (0..bounds.len() as u32).collect();
        let mut nodes: Vec<Bvh2Node> = Vec::with_capacity(2 * bounds.len());
        nodes.push(Bvh2Node { bounds: Aabb::EMPTY, kind: NodeKind::Leaf { first: 0, count: 0 } });
        let mut todo = alloc::vec![Work { slot: 0, start: 0, end: prims.len(), depth: 0 }];
        let mut bins = alloc::vec![Bin::EMPTY; cfg.bins];
        let mut right_area = alloc::vec![0.0f32; cfg.bins];
        while let Some(w) = todo.pop() {
            let range = &mut prims[w.start..w.end];
            let (node_bounds, cbounds) = range.iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(b, c), &p| {
                (b.union(bounds[p as usize]), c.grow(centroids[p as usize]))
            });
            nodes[w.slot].bounds = node_bounds;
            let count = range.len();
            let leaf = NodeKind::Leaf { first: w.start as u32, count: count as u32 };
            if count == 1 || w.depth >= cfg.max_depth {
                nodes[w.slot].kind = leaf;
                continue;
            }
            let best = best_binned_split(range, bounds, &centroids, cbounds, &cfg, &mut bins, &mut right_area);
            if keeps_leaf(&cfg, count, node_bounds, best.map(|(_, _, cost)| cost)) {
                nodes[w.slot].kind = leaf;
                continue;
            }
            let mid = match best {
                Some((axis, split, _)) => partition_binned(range, &centroids, cbounds, axis, split, cfg.bins),
                None => 0,
            };
            let mid = if mid == 0 || mid == count { median_split(range, &centroids, cbounds) } else { mid };
            let left = nodes.len();
            nodes.push(Bvh2Node { bounds: Aabb::EMPTY, kind: leaf });
            nodes.push(Bvh2Node { bounds: Aabb::EMPTY, kind: leaf });
            nodes[w.slot].kind = NodeKind::Internal { left: left as u32, right: left as u32 + 1 };
            todo.push(Work { slot: left + 1, start: w.start + mid, end: w.end, depth: w.depth + 1 });
            todo.push(Work { slot: left, start: w.start, end: w.start + mid, depth: w.depth + 1 });
        }
        Bvh2::from_nodes(&nodes, 0, prims)
    }
}

/// Whether a node of `count` primitives in box `node_bounds` stays a leaf, given the unnormalized
/// cost of its best split (`None`: no split separates it): when the split costs at least the leaf
/// and the leaf is within [`SahConfig::max_leaf_size`]. `cfg` is normalized (`leaf_block` at
/// least 1).
pub(super) fn keeps_leaf(cfg: &SahConfig, count: usize, node_bounds: Aabb, split_cost: Option<f32>) -> bool {
    if count as u32 > cfg.max_leaf_size {
        return false;
    }
    let leaf_cost = cfg.intersection_cost * cfg.leaf_tests(count as u32);
    let area = node_bounds.half_area().max(f32::MIN_POSITIVE);
    split_cost.is_none_or(|c| cfg.traversal_cost + cfg.intersection_cost * c / area >= leaf_cost)
}

/// Moves the primitives of `range` whose centroid bins below `split` on `axis` to its front;
/// returns how many there are.
pub(super) fn partition_binned(
    range: &mut [u32],
    centroids: &[Vec3],
    cbounds: Aabb,
    axis: usize,
    split: usize,
    bins: usize,
) -> usize {
    let k = bin_scale(cbounds, axis, bins);
    let mut i = 0;
    for j in 0..range.len() {
        if bin_of(centroids[range[j] as usize][axis], cbounds.min[axis], k, bins) < split {
            range.swap(i, j);
            i += 1;
        }
    }
    i
}

/// The boxes of the two sides [`partition_binned`] would make of `range`, without moving it.
pub(super) fn binned_sides(
    range: &[u32],
    bounds: &[Aabb],
    centroids: &[Vec3],
    cbounds: Aabb,
    axis: usize,
    split: usize,
    bins: usize,
) -> (Aabb, Aabb) {
    let k = bin_scale(cbounds, axis, bins);
    range.iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(l, r), &p| {
        if bin_of(centroids[p as usize][axis], cbounds.min[axis], k, bins) < split {
            (l.union(bounds[p as usize]), r)
        } else {
            (l, r.union(bounds[p as usize]))
        }
    })
}

/// Where binning cannot separate (coincident centroids): orders `range` by centroid on the widest
/// axis of `cbounds`, ties broken by id so the tree is deterministic, and returns the middle.
pub(super) fn median_split(range: &mut [u32], centroids: &[Vec3], cbounds: Aabb) -> usize {
    let axis = cbounds.extent().max_position();
    range
        .sort_unstable_by(|&a, &b| centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis]).then(a.cmp(&b)));
    range.len() / 2
}

#[inline]
fn bin_scale(cbounds: Aabb, axis: usize, bins: usize) -> f32 {
    let e = cbounds.max[axis] - cbounds.min[axis];
    if e > 0.0 {
        bins as f32 / e
    } else {
        0.0
    }
}

#[inline]
fn bin_of(c: f32, min: f32, scale: f32, bins: usize) -> usize {
    (((c - min) * scale) as usize).min(bins - 1)
}

/// The best (axis, first bin of the right side, unnormalized cost `A_l T_l + A_r T_r`, `T` the
/// leaf tests of a side's triangles).
pub(super) fn best_binned_split(
    range: &[u32],
    bounds: &[Aabb],
    centroids: &[Vec3],
    cbounds: Aabb,
    cfg: &SahConfig,
    bins: &mut [Bin],
    right_area: &mut [f32],
) -> Option<(usize, usize, f32)> {
    let mut best: Option<(usize, usize, f32)> = None;
    for axis in 0..3 {
        let scale = bin_scale(cbounds, axis, cfg.bins);
        if scale == 0.0 || !scale.is_finite() {
            continue;
        }
        bins.fill(Bin::EMPTY);
        for &p in range {
            let b = &mut bins[bin_of(centroids[p as usize][axis], cbounds.min[axis], scale, cfg.bins)];
            b.bounds = b.bounds.union(bounds[p as usize]);
            b.count += 1;
        }
        // Sweep from the right, recording area * count of everything at or right of each bin.
        let (mut acc, mut n) = (Aabb::EMPTY, 0u32);
        for i in (1..cfg.bins).rev() {
            acc = acc.union(bins[i].bounds);
            n += bins[i].count;
            right_area[i] = acc.half_area() * cfg.leaf_tests(n);
        }
        let (mut acc, mut n) = (Aabb::EMPTY, 0u32);
        for i in 1..cfg.bins {
            acc = acc.union(bins[i - 1].bounds);
            n += bins[i - 1].count;
            if n == 0 || n as usize == range.len() {
                continue;
            }
            let cost = acc.half_area() * cfg.leaf_tests(n) + right_area[i];
            if best.is_none_or(|(_, _, c)| cost < c) {
                best = Some((axis, i, cost));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize) -> Vec<Triangle> {
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (i as f32, j as f32);
                t.push(Triangle::new(Vec3::new(x, y, 0.0), Vec3::new(x + 1.0, y, 0.0), Vec3::new(x, y + 1.0, 0.0)));
            }
        }
        t
    }

    #[test]
    fn builds_a_valid_tree_over_every_primitive() {
        let tris = grid(30);
        let bvh = SahBuilder::default().build(&tris).unwrap();
        let s = bvh.stats();
        assert_eq!(s.leaves, s.internal_nodes + 1);
        assert!(s.max_leaf_size <= 8);
        // Every node's bounds hold its children's.
        for n in bvh.nodes() {
            if let NodeKind::Internal { left, right } = n.kind {
                assert!(n.bounds.contains(&bvh.nodes()[left as usize].bounds));
                assert!(n.bounds.contains(&bvh.nodes()[right as usize].bounds));
            }
        }
        let mut order = bvh.prim_order().to_vec();
        order.sort_unstable();
        assert_eq!(order, (0..900).collect::<Vec<u32>>());
    }

    #[test]
    fn coincident_triangles_respect_the_leaf_size() {
        let t = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let bvh = SahBuilder::default().build(&alloc::vec![t; 100]).unwrap();
        assert!(bvh.stats().max_leaf_size <= 8);
    }

    #[test]
    fn leaves_costed_per_block_fill_their_blocks() {
        let tris = grid(40);
        let build = |leaf_block| SahBuilder::new(SahConfig { leaf_block, ..SahConfig::default() }).build(&tris);
        let (per_triangle, per_block) = (build(1).unwrap().stats(), build(4).unwrap().stats());
        let mean = |s: &crate::bvh2::TreeStats| tris.len() as f64 / s.leaves as f64;
        assert!(mean(&per_block) > 1.5 * mean(&per_triangle), "{per_block:?} against {per_triangle:?}");
        assert!(per_block.max_leaf_size <= 8);
        assert_eq!(SahConfig { leaf_block: 4, ..SahConfig::default() }.leaf_tests(5), 2.0);
        assert_eq!(SahConfig { leaf_block: 0, ..SahConfig::default() }.leaf_tests(5), 5.0, "0 counts as 1");
    }

    #[test]
    fn empty_input_is_an_error() {
        assert_eq!(SahBuilder::default().build(&[]).unwrap_err(), Error::EmptyScene);
    }
}
