//! The references of a build (a primitive and the box of its part) and a node's partition by a
//! spatial split.

use super::spatial_bins::SpatialSplit;
use crate::geometry::clip::split_bounds;
use crate::geometry::Triangle;
use crate::Aabb;
use alloc::vec::Vec;
use glam::Vec3;

/// Every reference made so far, by reference id: a node holds a list of ids, and a reference is
/// in one node's list at a time.
pub(super) struct References {
    /// The primitive referenced.
    pub prim: Vec<u32>,
    /// The box of its part (the whole triangle's box until a spatial split cuts it).
    pub bounds: Vec<Aabb>,
    /// The centre of `bounds`, which object splits bin.
    pub centroids: Vec<Vec3>,
}

/// Where a spatial split sends a reference.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Side {
    Left,
    Right,
    Both,
}

impl References {
    /// One reference per triangle, with its whole box.
    pub fn new(tri_bounds: &[Aabb]) -> Self {
        References {
            prim: (0..tri_bounds.len() as u32).collect(),
            bounds: tri_bounds.to_vec(),
            centroids: tri_bounds.iter().map(Aabb::center).collect(),
        }
    }

    /// The box of references `ids`, and the box of their centroids.
    pub fn bounds_of(&self, ids: &[u32]) -> (Aabb, Aabb) {
        ids.iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(b, c), &r| {
            (b.union(self.bounds[r as usize]), c.grow(self.centroids[r as usize]))
        })
    }

    /// Partitions references `ids` by `split`: a reference wholly on one side of the plane goes
    /// there; one that straddles it is cut in two by clipping its triangle, or kept whole on one
    /// side where that is cheaper (the paper's reference unsplitting) or the budget `spare` of new
    /// references is spent. `None`, with nothing changed, where a side would be empty.
    pub fn split(
        &mut self,
        ids: &[u32],
        split: &SpatialSplit,
        triangles: &[Triangle],
        spare: &mut usize,
    ) -> Option<(Vec<u32>, Vec<u32>)> {
        let (k, plane) = (split.axis, split.plane);
        let (a_left, a_right) = (split.left.half_area(), split.right.half_area());
        let (n_left, n_right) = (split.left_count as f32, split.right_count as f32);
        let mut budget = *spare;
        let sides: Vec<Side> = ids
            .iter()
            .map(|&r| {
                let b = self.bounds[r as usize];
                if b.min[k] >= plane {
                    return Side::Right;
                }
                if b.max[k] <= plane {
                    return Side::Left;
                }
                // Unsplitting: the cost of the split with this reference on both sides, wholly
                // left, or wholly right (plain counts, as in the paper).
                let both = a_left * n_left + a_right * n_right;
                let left = split.left.union(b).half_area() * n_left + a_right * (n_right - 1.0);
                let right = a_left * (n_left - 1.0) + split.right.union(b).half_area() * n_right;
                if budget > 0 && both < left.min(right) {
                    budget -= 1;
                    Side::Both
                } else if left <= right {
                    Side::Left
                } else {
                    Side::Right
                }
            })
            .collect();
        if !sides.iter().any(|&s| s != Side::Right) || !sides.iter().any(|&s| s != Side::Left) {
            return None;
        }
        let (mut left, mut right) = (Vec::with_capacity(ids.len()), Vec::with_capacity(ids.len()));
        for (&r, side) in ids.iter().zip(sides) {
            match side {
                Side::Left => left.push(r),
                Side::Right => right.push(r),
                Side::Both => {
                    let p = self.prim[r as usize] as usize;
                    let b = self.bounds[r as usize];
                    match split_bounds(&triangles[p], &b, k, plane) {
                        (Some(l), Some(rb)) => {
                            self.set(r, l);
                            right.push(self.push(p as u32, rb));
                            left.push(r);
                            *spare -= 1;
                        }
                        (None, Some(rb)) => {
                            self.set(r, rb);
                            right.push(r);
                        }
                        (Some(l), None) => {
                            self.set(r, l);
                            left.push(r);
                        }
                        // The triangle meets its own box, so clipping finds a part on some side;
                        // should rounding say otherwise, the whole box stays, on the left.
                        (None, None) => left.push(r),
                    }
                }
            }
        }
        // Clipping can move a cut reference wholly to one side and empty the other.
        if left.is_empty() || right.is_empty() {
            left.append(&mut right);
            let mid = left.len() / 2;
            right = left.split_off(mid);
        }
        Some((left, right))
    }

    fn set(&mut self, r: u32, bounds: Aabb) {
        self.bounds[r as usize] = bounds;
        self.centroids[r as usize] = bounds.center();
    }

    fn push(&mut self, prim: u32, bounds: Aabb) -> u32 {
        self.prim.push(prim);
        self.bounds.push(bounds);
        self.centroids.push(bounds.center());
        (self.prim.len() - 1) as u32
    }
}
