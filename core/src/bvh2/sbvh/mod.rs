//! A BVH2 builder with spatial splits (Stich, Friedrich & Dietrich 2009, "Spatial Splits in
//! Bounding Volume Hierarchies"): where the best object split leaves two children that overlap, a
//! split by a plane that cuts triangles in two is tried too, each side keeping a reference to the
//! part of a cut triangle on its side (the box of that part, from clipping).
//!
//! - `references.rs`: the references (a primitive and the box of its part) and the partition of a
//!   node's references by a spatial split, with the paper's reference unsplitting;
//! - `spatial_bins.rs`: the spatial split candidates, binned (the paper's "chopped" references).
//!
//! Object splits are the binned SAH builder's ([`super::SahBuilder`], centroids of the reference
//! boxes binned), where the paper sweeps sorted references: binning is what raytrail's SAH builder
//! does, and it keeps the two builders' trees alike where no spatial split pays. A node tries
//! spatial splits only when the object split's children overlap by more than
//! [`SbvhConfig::overlap_threshold`] of the root's area (the paper's alpha) and the tree is within
//! its reference budget, so meshes of small even triangles pay little for them.
//!
//! The tree references a primitive from each leaf that holds a part of it
//! ([`Bvh2::from_split_nodes`]); every method traverses it as any other tree. A leaf's box holds
//! the parts of its triangles, not the whole triangles; the clipping rounds outward, so a point of
//! a triangle lies in the box of some leaf that references it, and a ray that hits the triangle
//! there enters that leaf.

mod references;
mod spatial_bins;

use super::sah::{best_binned_split, binned_sides, keeps_leaf, median_split, partition_binned, Bin};
use super::tree::{Bvh2, Bvh2Node, NodeKind};
use super::SahConfig;
use crate::geometry::Triangle;
use crate::{Aabb, Error};
use alloc::vec::Vec;
use references::References;
use spatial_bins::SpatialBins;

/// Settings of the spatial-split builder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SbvhConfig {
    /// The cost model, bins and leaf limits, as for the binned SAH builder.
    pub sah: SahConfig,
    /// Spatial splits are tried at a node only where the best object split's children overlap
    /// by more than this fraction of the root's half area (the paper's alpha). The paper used
    /// `1e-5`; `1e-3` keeps all but 0.4% of that tree cost on Sponza, the kitchen and the dragon
    /// and builds 2-4 times as fast (`docs/notes/*-spatial-splits.md`).
    pub overlap_threshold: f32,
    /// At most this many references per triangle in the whole tree (at least 1, which allows no
    /// spatial split): the budget that bounds the tree's memory.
    pub max_references_per_triangle: f32,
}

impl Default for SbvhConfig {
    fn default() -> Self {
        Self { sah: SahConfig::default(), overlap_threshold: 1e-3, max_references_per_triangle: 1.5 }
    }
}

/// A BVH2 builder with spatial splits (SBVH, Stich et al. 2009).
#[derive(Clone, Copy, Debug, Default)]
pub struct SbvhBuilder {
    /// Settings.
    pub config: SbvhConfig,
}

struct Work {
    slot: usize,
    refs: Vec<u32>,
    depth: u32,
}

impl SbvhBuilder {
    /// A builder with the given settings.
    pub fn new(config: SbvhConfig) -> Self {
        Self { config }
    }

    /// Builds the canonical tree over `triangles` (primitive id = index); a triangle cut by
    /// spatial splits is referenced from several leaves.
    pub fn build(&self, triangles: &[Triangle]) -> Result<Bvh2, Error> {
        if triangles.is_empty() {
            return Err(Error::EmptyScene);
        }
        let cfg = self.config.sah.normalized();
        let tri_bounds: Vec<Aabb> = triangles.iter().map(Triangle::bounds).collect();
        let mut refs = References::new(&tri_bounds);
        let budget = self.config.max_references_per_triangle.max(1.0);
        let mut spare = ((triangles.len() as f64) * f64::from(budget - 1.0)) as usize;
        let root = tri_bounds.iter().fold(Aabb::EMPTY, |b, &t| b.union(t));
        let min_overlap = self.config.overlap_threshold * root.half_area();
        let mut nodes: Vec<Bvh2Node> = Vec::with_capacity(2 * triangles.len());
        nodes.push(Bvh2Node { bounds: Aabb::EMPTY, kind: NodeKind::Leaf { first: 0, count: 0 } });
        let mut prim_order: Vec<u32> = Vec::with_capacity(triangles.len());
        let mut todo = alloc::vec![Work { slot: 0, refs: (0..triangles.len() as u32).collect(), depth: 0 }];
        let mut bins = alloc::vec![Bin::EMPTY; cfg.bins];
        let mut right_area = alloc::vec![0.0f32; cfg.bins];
        let mut spatial_bins = SpatialBins::new(cfg.bins);
        while let Some(mut w) = todo.pop() {
            let (node_bounds, cbounds) = refs.bounds_of(&w.refs);
            nodes[w.slot].bounds = node_bounds;
            let count = w.refs.len();
            if count == 1 || w.depth >= cfg.max_depth {
                emit_leaf(&mut nodes[w.slot], &mut prim_order, &w.refs, &refs);
                continue;
            }
            let object =
                best_binned_split(&w.refs, &refs.bounds, &refs.centroids, cbounds, &cfg, &mut bins, &mut right_area);
            let overlap = object.map_or(0.0, |(axis, split, _)| {
                let (l, r) = binned_sides(&w.refs, &refs.bounds, &refs.centroids, cbounds, axis, split, cfg.bins);
                overlap(l, r)
            });
            let spatial = (spare > 0 && overlap > min_overlap)
                .then(|| spatial_bins.best(&w.refs, &refs, triangles, node_bounds, &cfg))
                .flatten()
                .filter(|s| object.is_none_or(|(_, _, cost)| s.cost < cost));
            let best_cost = spatial.as_ref().map(|s| s.cost).or(object.map(|(_, _, cost)| cost));
            if keeps_leaf(&cfg, count, node_bounds, best_cost) {
                emit_leaf(&mut nodes[w.slot], &mut prim_order, &w.refs, &refs);
                continue;
            }
            let split = spatial.and_then(|s| refs.split(&w.refs, &s, triangles, &mut spare));
            let (left, right) = match split {
                Some(sides) => sides,
                None => {
                    let mid = object.map_or(0, |(axis, split, _)| {
                        partition_binned(&mut w.refs, &refs.centroids, cbounds, axis, split, cfg.bins)
                    });
                    let mid = if mid == 0 || mid == count {
                        median_split(&mut w.refs, &refs.centroids, cbounds)
                    } else {
                        mid
                    };
                    let right = w.refs.split_off(mid);
                    (w.refs, right)
                }
            };
            let slot = nodes.len();
            let placeholder = Bvh2Node { bounds: Aabb::EMPTY, kind: NodeKind::Leaf { first: 0, count: 0 } };
            nodes.extend([placeholder, placeholder]);
            nodes[w.slot].kind = NodeKind::Internal { left: slot as u32, right: slot as u32 + 1 };
            todo.push(Work { slot: slot + 1, refs: right, depth: w.depth + 1 });
            todo.push(Work { slot, refs: left, depth: w.depth + 1 });
        }
        Bvh2::from_split_nodes(&nodes, 0, prim_order, triangles.len())
    }
}

/// Makes `node` a leaf of references `ids`, their primitives appended to `prim_order`.
fn emit_leaf(node: &mut Bvh2Node, prim_order: &mut Vec<u32>, ids: &[u32], refs: &References) {
    let first = prim_order.len() as u32;
    prim_order.extend(ids.iter().map(|&r| refs.prim[r as usize]));
    node.kind = NodeKind::Leaf { first, count: ids.len() as u32 };
}

/// The half area of the common part of boxes `a` and `b` (0 where they are disjoint).
fn overlap(a: Aabb, b: Aabb) -> f32 {
    let common = a.intersection(b);
    if common.is_empty() {
        0.0
    } else {
        common.half_area()
    }
}

#[cfg(test)]
mod tests;
