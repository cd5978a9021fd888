//! The expected cost of a ray through a finished tree under the surface-area heuristic, the
//! measure [`SahBuilder`](super::SahBuilder) minimizes split by split, summed over the whole tree.
//!
//! It lets trees from different builders be compared before any ray is traced: a ray that
//! enters the root enters a node with probability (node's area / root's area), so the expected
//! cost is the area-weighted sum of the node costs.

use super::{Bvh2, NodeKind, SahConfig};

impl SahConfig {
    /// Expected cost of a ray that enters the root of `bvh`: every internal node's half area
    /// times `traversal_cost`, plus every leaf's half area times `intersection_cost` per leaf
    /// test ([`SahConfig::leaf_tests`]), over the root's half area. Where the root has no
    /// area (every triangle in one point), the sum is not divided, so trees still compare.
    pub fn tree_cost(&self, bvh: &Bvh2) -> f64 {
        let nodes = bvh.nodes();
        let sum: f64 = nodes
            .iter()
            .map(|n| {
                let per_area = match n.kind {
                    NodeKind::Internal { .. } => f64::from(self.traversal_cost),
                    NodeKind::Leaf { count, .. } => {
                        f64::from(self.intersection_cost) * f64::from(self.leaf_tests(count))
                    }
                };
                f64::from(n.bounds.half_area()) * per_area
            })
            .sum();
        let root = f64::from(nodes[0].bounds.half_area());
        if root > 0.0 && root.is_finite() {
            sum / root
        } else {
            sum
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh2::SahBuilder;
    use crate::geometry::Triangle;
    use glam::Vec3;

    fn tri(x: f32) -> Triangle {
        Triangle::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 0.0, 0.0), Vec3::new(x, 1.0, 1.0))
    }

    #[test]
    fn a_single_leaf_costs_its_leaf_tests() {
        let cfg = SahConfig::default();
        let bvh = SahBuilder::default().build(&[tri(0.0), tri(0.5), tri(1.0)]).unwrap();
        assert_eq!(bvh.nodes().len(), 1, "three triangles make one leaf");
        assert_eq!(cfg.tree_cost(&bvh), 1.0);
        let per_triangle = SahConfig { leaf_block: 1, intersection_cost: 2.0, ..cfg };
        assert_eq!(per_triangle.tree_cost(&bvh), 6.0);
    }

    #[test]
    fn internal_nodes_and_leaves_weigh_by_their_area() {
        let cfg = SahConfig { max_leaf_size: 1, ..SahConfig::default() };
        let far = [tri(0.0), tri(100.0)];
        let bvh = SahBuilder::new(cfg).build(&far).unwrap();
        let nodes = bvh.nodes();
        assert_eq!(nodes.len(), 3);
        let root = f64::from(nodes[0].bounds.half_area());
        let leaves = f64::from(nodes[1].bounds.half_area() + nodes[2].bounds.half_area());
        let want = 1.0 + leaves / root;
        assert!((cfg.tree_cost(&bvh) - want).abs() < 1e-9, "{} against {want}", cfg.tree_cost(&bvh));
    }

    #[test]
    fn a_tree_without_area_still_has_a_cost() {
        let p = Vec3::splat(1.0);
        let point = Triangle::new(p, p, p);
        let bvh = SahBuilder::default().build(&[point; 6]).unwrap();
        let cost = SahConfig::default().tree_cost(&bvh);
        assert!(cost.is_finite() && cost >= 0.0, "{cost}");
    }
}
