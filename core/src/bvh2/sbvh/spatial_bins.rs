//! Spatial split candidates: the node's box cut into equal slabs along each axis, every
//! reference chopped into the slabs it spans (the box of its triangle's part in each, from
//! clipping), and the planes between slabs priced by the surface-area heuristic, a reference
//! counted on the left of a plane when it starts before it and on the right when it ends after it.

use super::references::References;
use crate::bvh2::SahConfig;
use crate::geometry::clip::split_bounds;
use crate::geometry::Triangle;
use crate::Aabb;
use alloc::vec::Vec;

/// The best spatial split of a node.
#[derive(Clone, Copy, Debug)]
pub(super) struct SpatialSplit {
    /// The axis the plane is normal to.
    pub axis: usize,
    /// Where the plane lies on it.
    pub plane: f32,
    /// Unnormalized cost `A_l T_l + A_r T_r`, as the object splits are priced.
    pub cost: f32,
    /// The box of everything left of the plane, and the references it holds.
    pub left: Aabb,
    pub left_count: u32,
    /// The box of everything right of it, and the references it holds.
    pub right: Aabb,
    pub right_count: u32,
}

#[derive(Clone, Copy)]
struct Slab {
    bounds: Aabb,
    /// References that start in this slab.
    enter: u32,
    /// References that end in it.
    exit: u32,
}

/// Scratch space of the search, kept across nodes.
pub(super) struct SpatialBins {
    count: usize,
    slabs: Vec<Slab>,
    planes: Vec<f32>,
    /// Per slab, from the right: the box, the references and the cost of everything at or right
    /// of it.
    right: Vec<(Aabb, u32, f32)>,
}

impl SpatialBins {
    /// Search space for `count` slabs per axis.
    pub fn new(count: usize) -> Self {
        SpatialBins { count: count.max(2), slabs: Vec::new(), planes: Vec::new(), right: Vec::new() }
    }

    /// The cheapest spatial split of the node of references `ids` and box `node`, if some plane
    /// leaves references on both sides.
    pub fn best(
        &mut self,
        ids: &[u32],
        refs: &References,
        triangles: &[Triangle],
        node: Aabb,
        cfg: &SahConfig,
    ) -> Option<SpatialSplit> {
        let mut best: Option<SpatialSplit> = None;
        for axis in 0..3 {
            if !self.chop(axis, ids, refs, triangles, node) {
                continue;
            }
            let n = self.slabs.len();
            self.right.clear();
            self.right.resize(n, (Aabb::EMPTY, 0, 0.0));
            let (mut acc, mut count) = (Aabb::EMPTY, 0u32);
            for i in (1..n).rev() {
                acc = acc.union(self.slabs[i].bounds);
                count += self.slabs[i].exit;
                self.right[i] = (acc, count, acc.half_area() * cfg.leaf_tests(count));
            }
            let (mut acc, mut count) = (Aabb::EMPTY, 0u32);
            for i in 1..n {
                acc = acc.union(self.slabs[i - 1].bounds);
                count += self.slabs[i - 1].enter;
                let (right, right_count, right_cost) = self.right[i];
                if count == 0 || right_count == 0 || acc.is_empty() || right.is_empty() {
                    continue;
                }
                let cost = acc.half_area() * cfg.leaf_tests(count) + right_cost;
                if best.is_none_or(|b| cost < b.cost) {
                    let plane = self.planes[i - 1];
                    best = Some(SpatialSplit { axis, plane, cost, left: acc, left_count: count, right, right_count });
                }
            }
        }
        best
    }

    /// Bins references `ids` into the slabs of `node` along `axis`; false where the box is flat
    /// along it (no plane inside).
    fn chop(&mut self, axis: usize, ids: &[u32], refs: &References, triangles: &[Triangle], node: Aabb) -> bool {
        let (lo, hi) = (node.min[axis], node.max[axis]);
        let step = (hi - lo) / self.count as f32;
        self.planes.clear();
        for i in 1..self.count {
            let p = lo + step * i as f32;
            // Rounding may repeat a plane or put one on a face; only planes strictly inside, in
            // increasing order, cut anything.
            if p > lo && p < hi && self.planes.last().is_none_or(|&q| p > q) {
                self.planes.push(p);
            }
        }
        if self.planes.is_empty() {
            return false;
        }
        self.slabs.clear();
        self.slabs.resize(self.planes.len() + 1, Slab { bounds: Aabb::EMPTY, enter: 0, exit: 0 });
        for &r in ids {
            let b = refs.bounds[r as usize];
            // The slab a reference starts in counts planes at or below its start; the one it
            // ends in, planes below its end. A flat reference on a plane starts and ends right
            // of it, as the partition sends it.
            let first = self.planes.partition_point(|&p| p <= b.min[axis]);
            let last = self.planes.partition_point(|&p| p < b.max[axis]).max(first);
            self.slabs[first].enter += 1;
            self.slabs[last].exit += 1;
            let p = refs.prim[r as usize] as usize;
            let mut rest = b;
            for j in first..last {
                let (below, above) = split_bounds(&triangles[p], &rest, axis, self.planes[j]);
                if let Some(below) = below {
                    self.slabs[j].bounds = self.slabs[j].bounds.union(below);
                }
                match above {
                    Some(above) => rest = above,
                    None => {
                        rest = Aabb::EMPTY;
                        break;
                    }
                }
            }
            self.slabs[last].bounds = self.slabs[last].bounds.union(rest);
        }
        true
    }
}
