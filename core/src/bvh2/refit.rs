//! Refitting: new boxes for moved triangles, the topology kept.
//!
//! A tree's topology (which nodes are whose children, which primitives each leaf holds) says
//! nothing about where the triangles are; only the boxes do. After the vertices move, boxes made
//! again bottom-up from the triangles bound them as tightly as the topology allows, in one pass
//! over the nodes. Every table made from the topology alone stays valid: node keys, bit trails,
//! the perfect hashes over keys, node addresses and links of the layouts. Only the tree's quality
//! (its SAH cost) drifts as the triangles move away from where it was built for.

use super::tree::{Bvh2, NodeKind};
use crate::geometry::Triangle;
use crate::stream::{Parallel, Serial};
use crate::{Aabb, Error};

/// Nodes a task of a parallel refit takes at once.
pub(crate) const REFIT_CHUNK: usize = 4096;

impl Bvh2 {
    /// Makes every box again from `triangles` (by primitive id, as many as the tree holds): a leaf's
    /// box is the union of its triangles' boxes, an internal node's the union of its children's.
    /// Linear in the tree's size; the topology, and with it [`Bvh2::keys`], is unchanged.
    ///
    /// [`Error::TreeMismatch`] when the triangle count is not the tree's.
    pub fn refit(&mut self, triangles: &[Triangle]) -> Result<(), Error> {
        self.refit_with(triangles, &Serial)
    }

    /// [`Bvh2::refit`] with the leaves' boxes (the reads of the triangles, most of the time) made
    /// on `par`; the inner nodes follow in one backward sweep. The boxes are the same either way.
    pub fn refit_with(&mut self, triangles: &[Triangle], par: &impl Parallel) -> Result<(), Error> {
        if triangles.len() != self.prim_count() {
            return Err(Error::TreeMismatch {
                node: 0,
                why: "refit: the new triangle count differs from the tree's primitive count",
            });
        }
        let (nodes, prim_order) = self.nodes_and_order_mut();
        let leaf_box = |first: u32, count: u32| {
            prim_order[first as usize..(first + count) as usize]
                .iter()
                .fold(Aabb::EMPTY, |b, &p| b.union(triangles[p as usize].bounds()))
        };
        par.for_each_chunk(nodes, REFIT_CHUNK, |_, piece| {
            for node in piece {
                if let NodeKind::Leaf { first, count } = node.kind {
                    node.bounds = leaf_box(first, count);
                }
            }
        });
        // Pre-order: every child has a larger index than its parent, so a backward sweep meets
        // children before parents.
        for i in (0..nodes.len()).rev() {
            if let NodeKind::Internal { left, right } = nodes[i].kind {
                nodes[i].bounds = nodes[left as usize].bounds.union(nodes[right as usize].bounds);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::bvh2::{Bvh2, NodeKind, SahBuilder};
    use crate::geometry::Triangle;
    use crate::Aabb;
    use glam::Vec3;

    fn grid(shift: f32) -> alloc::vec::Vec<Triangle> {
        (0..64)
            .map(|i| {
                let (x, y) = ((i % 8) as f32, (i / 8) as f32);
                let z = shift * (x * 0.37 + y * 0.11).sin();
                Triangle::new(Vec3::new(x, y, z), Vec3::new(x + 1.0, y, z), Vec3::new(x, y + 1.0, z * 0.5))
            })
            .collect()
    }

    /// Each box by its definition: the union of the triangles below it, found by walking down.
    fn box_below(bvh: &Bvh2, tris: &[Triangle], n: u32) -> Aabb {
        match bvh.nodes()[n as usize].kind {
            NodeKind::Leaf { first, count } => bvh.prim_order()[first as usize..(first + count) as usize]
                .iter()
                .fold(Aabb::EMPTY, |b, &p| b.union(tris[p as usize].bounds())),
            NodeKind::Internal { left, right } => box_below(bvh, tris, left).union(box_below(bvh, tris, right)),
        }
    }

    #[test]
    fn refit_boxes_are_the_unions_below_them_and_the_topology_is_kept() {
        let mut bvh = SahBuilder::default().build(&grid(0.0)).unwrap();
        // The builder's boxes are already the tight ones: refitting to the same triangles is no change.
        let built = bvh.nodes().to_vec();
        bvh.refit(&grid(0.0)).unwrap();
        assert_eq!(bvh.nodes(), &built[..]);
        let (kinds, keys) = (bvh.nodes().iter().map(|n| n.kind).collect::<alloc::vec::Vec<_>>(), bvh.keys());
        let moved = grid(3.0);
        assert!(bvh.check_bounds(&moved).is_err(), "the moved triangles leave the old boxes");
        bvh.refit(&moved).unwrap();
        bvh.check_bounds(&moved).unwrap();
        for n in 0..bvh.len() as u32 {
            assert_eq!(bvh.nodes()[n as usize].bounds, box_below(&bvh, &moved, n), "node {n}");
        }
        assert_eq!(bvh.nodes().iter().map(|n| n.kind).collect::<alloc::vec::Vec<_>>(), kinds);
        assert_eq!(bvh.keys(), keys);
        assert!(bvh.refit(&moved[1..]).is_err());
    }
}
