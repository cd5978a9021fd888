use super::KdNode;
use crate::{Aabb, Error};
use alloc::vec::Vec;

/// Shape figures of a kd-tree.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct KdStats {
    /// Inner nodes.
    pub inner_nodes: usize,
    /// Leaves, empty ones included.
    pub leaves: usize,
    /// Leaves without primitives.
    pub empty_leaves: usize,
    /// Depth of the deepest node (root: 0).
    pub depth: u32,
    /// Largest leaf.
    pub max_leaf_size: u32,
    /// Primitive references per triangle (a triangle straddling planes is in several leaves).
    pub refs_per_triangle: f64,
}

/// A kd-tree: nodes with the root at 0 and siblings adjacent, the primitive references its leaves
/// point into, and the scene bounds it partitions. Node identity in enumerations is the index.
#[derive(Clone, Debug)]
pub struct KdTree {
    nodes: Vec<KdNode>,
    prims: Vec<u32>,
    bounds: Aabb,
    stats: KdStats,
}

impl KdTree {
    /// Adopts nodes from a builder and checks them: children in range and after their parent
    /// (so there is no cycle), each node reached once, leaf ranges inside `prims`, every reference
    /// a primitive below `triangle_count`.
    pub fn from_parts(
        nodes: Vec<KdNode>,
        prims: Vec<u32>,
        bounds: Aabb,
        triangle_count: usize,
    ) -> Result<KdTree, Error> {
        if nodes.is_empty() {
            return Err(Error::MalformedTree("a kd-tree needs a root"));
        }
        if nodes.len() >= KdNode::LIMIT as usize || prims.len() >= KdNode::LIMIT as usize {
            return Err(Error::TreeTooLarge { what: "kd-tree", size: nodes.len().max(prims.len()) });
        }
        let mut stats = KdStats::default();
        let mut seen = alloc::vec![false; nodes.len()];
        let mut todo = alloc::vec![(0u32, 0u32)];
        while let Some((i, depth)) = todo.pop() {
            if core::mem::replace(&mut seen[i as usize], true) {
                return Err(Error::MalformedTree("a kd node is reached twice"));
            }
            stats.depth = stats.depth.max(depth);
            let n = nodes[i as usize];
            if n.is_leaf() {
                let (first, count) = (n.first() as usize, n.count() as usize);
                let refs = prims.get(first..first + count).ok_or(Error::MalformedTree("kd leaf range out of range"))?;
                if refs.iter().any(|&p| p as usize >= triangle_count) {
                    return Err(Error::MalformedTree("kd leaf references a missing triangle"));
                }
                stats.leaves += 1;
                stats.empty_leaves += (count == 0) as usize;
                stats.max_leaf_size = stats.max_leaf_size.max(count as u32);
            } else {
                let b = n.below();
                if b <= i || b as usize + 1 >= nodes.len() || !n.value.is_finite() {
                    return Err(Error::MalformedTree("kd children must follow their parent, within range"));
                }
                stats.inner_nodes += 1;
                todo.push((b, depth + 1));
                todo.push((b + 1, depth + 1));
            }
        }
        stats.refs_per_triangle = prims.len() as f64 / triangle_count.max(1) as f64;
        Ok(KdTree { nodes, prims, bounds, stats })
    }

    /// Nodes; the root is 0.
    pub fn nodes(&self) -> &[KdNode] {
        &self.nodes
    }

    /// Primitive references of the leaves.
    pub fn prims(&self) -> &[u32] {
        &self.prims
    }

    /// The box the tree partitions (the scene bounds).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Shape figures.
    pub fn stats(&self) -> KdStats {
        self.stats
    }

    /// Bytes of nodes and references.
    pub fn bytes(&self) -> usize {
        core::mem::size_of_val(self.nodes.as_slice()) + 4 * self.prims.len()
    }
}
