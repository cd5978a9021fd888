use crate::geometry::Triangle;
use crate::key::KeyWidth;
use crate::{Aabb, Error};
use alloc::vec::Vec;

/// What a canonical node is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeKind {
    /// Two children, by canonical index.
    Internal {
        /// Left child.
        left: u32,
        /// Right child.
        right: u32,
    },
    /// A run of `count` entries of [`Bvh2::prim_order`] starting at `first`.
    Leaf {
        /// First entry.
        first: u32,
        /// Number of primitives.
        count: u32,
    },
}

/// A node still to renumber: (old index, depth, the new parent and whether it is the right child).
type Pending = (u32, u32, Option<(usize, bool)>);

/// A node of the canonical tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bvh2Node {
    /// Bounds of everything below.
    pub bounds: Aabb,
    /// Children or primitives.
    pub kind: NodeKind,
}

/// Shape figures of a tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TreeStats {
    /// Internal nodes.
    pub internal_nodes: usize,
    /// Leaves.
    pub leaves: usize,
    /// Depth of the deepest node (root: 0).
    pub depth: u32,
    /// Largest leaf.
    pub max_leaf_size: u32,
    /// Key width the depth needs.
    pub key_width: KeyWidth,
}

/// The canonical binary BVH: nodes in pre-order (root 0, each left subtree before its right
/// sibling), every internal node with exactly two children.
///
/// Node identity everywhere in raytrail (enumerations, conformance reports) is the index here,
/// whatever layout a method traverses.
#[derive(Clone, Debug)]
pub struct Bvh2 {
    nodes: Vec<Bvh2Node>,
    prim_order: Vec<u32>,
    /// Distinct primitives: `prim_order.len()` unless references are split across leaves.
    prim_count: usize,
    stats: TreeStats,
}

impl Bvh2 {
    /// Adopts nodes and a primitive order from a builder, renumbering them into canonical
    /// pre-order from `root`, and checks the structure: every node reached once, every primitive
    /// referenced once, depth at most 63, sizes within the 2^30 addresses of [`super::NodeRef`].
    pub fn from_nodes(nodes: &[Bvh2Node], root: u32, prim_order: Vec<u32>) -> Result<Bvh2, Error> {
        let prim_count = prim_order.len();
        Self::adopt(nodes, root, prim_order, prim_count, false)
    }

    /// [`Bvh2::from_nodes`] for a builder with spatial splits: a primitive of `0..prim_count` may
    /// be referenced by several leaves (each holding the part of it inside its box), at most once
    /// by each, and must be referenced by one at least.
    pub fn from_split_nodes(
        nodes: &[Bvh2Node],
        root: u32,
        references: Vec<u32>,
        prim_count: usize,
    ) -> Result<Bvh2, Error> {
        Self::adopt(nodes, root, references, prim_count, true)
    }

    fn adopt(
        nodes: &[Bvh2Node],
        root: u32,
        prim_order: Vec<u32>,
        prim_count: usize,
        split: bool,
    ) -> Result<Bvh2, Error> {
        if nodes.is_empty() || prim_order.is_empty() || prim_count == 0 {
            return Err(Error::EmptyScene);
        }
        let mut out: Vec<Bvh2Node> = Vec::with_capacity(nodes.len());
        let mut seen = alloc::vec![false; nodes.len()];
        // The last leaf (new index) referencing each primitive; `u32::MAX` for none yet.
        let mut last_leaf = alloc::vec![u32::MAX; prim_count];
        let mut distinct = 0usize;
        let mut new_order: Vec<u32> = Vec::with_capacity(prim_order.len());
        let mut stats =
            TreeStats { internal_nodes: 0, leaves: 0, depth: 0, max_leaf_size: 0, key_width: KeyWidth::W32 };
        let mut todo: Vec<Pending> = alloc::vec![(root, 0, None)];
        while let Some((old, depth, patch)) = todo.pop() {
            let node = nodes.get(old as usize).ok_or(Error::MalformedTree("child index out of range"))?;
            if core::mem::replace(&mut seen[old as usize], true) {
                return Err(Error::MalformedTree("a node is reached twice"));
            }
            if depth > 63 {
                return Err(Error::TreeTooDeep { depth, max: 63 });
            }
            stats.depth = stats.depth.max(depth);
            let new = out.len() as u32;
            if let Some((p, right)) = patch {
                if let NodeKind::Internal { left, right: r } = &mut out[p].kind {
                    *(if right { r } else { left }) = new;
                }
            }
            match node.kind {
                NodeKind::Internal { left, right } => {
                    stats.internal_nodes += 1;
                    out.push(Bvh2Node {
                        bounds: node.bounds,
                        kind: NodeKind::Internal { left: u32::MAX, right: u32::MAX },
                    });
                    let slot = out.len() - 1;
                    // Right pushed first so the left subtree is numbered first (pre-order).
                    todo.push((right, depth + 1, Some((slot, true))));
                    todo.push((left, depth + 1, Some((slot, false))));
                }
                NodeKind::Leaf { first, count } => {
                    let range = prim_order
                        .get(first as usize..first as usize + count as usize)
                        .ok_or(Error::MalformedTree("leaf range out of range"))?;
                    if count == 0 {
                        return Err(Error::MalformedTree("empty leaf"));
                    }
                    let start = new_order.len() as u32;
                    for &p in range {
                        let last =
                            last_leaf.get_mut(p as usize).ok_or(Error::MalformedTree("primitive id out of range"))?;
                        match core::mem::replace(last, new) {
                            u32::MAX => distinct += 1,
                            l if l == new => return Err(Error::MalformedTree("a leaf references a primitive twice")),
                            _ if !split => return Err(Error::MalformedTree("a primitive is referenced twice")),
                            _ => {}
                        }
                        new_order.push(p);
                    }
                    stats.leaves += 1;
                    stats.max_leaf_size = stats.max_leaf_size.max(count);
                    out.push(Bvh2Node { bounds: node.bounds, kind: NodeKind::Leaf { first: start, count } });
                }
            }
        }
        if new_order.len() != prim_order.len() || distinct != prim_count {
            return Err(Error::MalformedTree("some primitives are in no leaf"));
        }
        if out.len() >= super::NodeRef::LIMIT as usize {
            return Err(Error::TreeTooLarge { what: "node count", size: out.len() });
        }
        stats.key_width = KeyWidth::for_depth(stats.depth).ok_or(Error::TreeTooDeep { depth: stats.depth, max: 63 })?;
        Ok(Bvh2 { nodes: out, prim_order: new_order, prim_count, stats })
    }

    /// Checks that this tree bounds `triangles`: one primitive id per triangle, every internal
    /// box holding its children's boxes, and every triangle's box covered by the leaves that
    /// reference it (the union of each leaf's box cut to the triangle's box is the whole of it;
    /// for a tree without split references, its one leaf's box holds it). A tree built for other
    /// triangles fails ([`Error::TreeMismatch`]); a tree that passes without split references
    /// finds every hit, since no triangle lies outside the boxes a ray must enter to reach it.
    /// For split references the check is necessary, not sufficient: it bounds the triangle's box,
    /// not the triangle's every point. Linear in the tree's size.
    pub fn check_bounds(&self, triangles: &[Triangle]) -> Result<(), Error> {
        if self.prim_count != triangles.len() {
            return Err(Error::TreeMismatch {
                node: 0,
                why: "its primitive count differs from the scene's triangle count",
            });
        }
        // Per primitive: the union of its leaves' boxes cut to its own, and the last such leaf.
        let mut covered = alloc::vec![(Aabb::EMPTY, 0usize); self.prim_count];
        for (i, node) in self.nodes.iter().enumerate() {
            match node.kind {
                NodeKind::Internal { left, right } => {
                    let fits = [left, right]
                        .iter()
                        .all(|&c| self.nodes.get(c as usize).is_some_and(|child| node.bounds.contains(&child.bounds)));
                    if !fits {
                        return Err(Error::TreeMismatch { node: i, why: "its box does not hold a child's box" });
                    }
                }
                NodeKind::Leaf { first, count } => {
                    for &p in &self.prim_order[first as usize..(first + count) as usize] {
                        let own = triangles[p as usize].bounds();
                        let cut = own.intersection(node.bounds);
                        let (cover, leaf) = &mut covered[p as usize];
                        if !cut.is_empty() {
                            *cover = cover.union(cut);
                        }
                        *leaf = i;
                    }
                }
            }
        }
        for (p, (cover, leaf)) in covered.iter().enumerate() {
            if !cover.contains(&triangles[p].bounds()) {
                return Err(Error::TreeMismatch { node: *leaf, why: "its box does not hold one of its triangles" });
            }
        }
        Ok(())
    }

    /// The nodes to write and the primitive order to read, for [`Bvh2::refit`], which changes
    /// boxes only.
    pub(super) fn nodes_and_order_mut(&mut self) -> (&mut [Bvh2Node], &[u32]) {
        (&mut self.nodes, &self.prim_order)
    }

    /// Nodes in canonical order.
    pub fn nodes(&self) -> &[Bvh2Node] {
        &self.nodes
    }

    /// Primitive ids in leaf order: one entry per reference, so a primitive split across leaves
    /// appears once in each.
    pub fn prim_order(&self) -> &[u32] {
        &self.prim_order
    }

    /// Distinct primitives (the scene's triangle count).
    pub fn prim_count(&self) -> usize {
        self.prim_count
    }

    /// Whether some primitive is referenced by more than one leaf (a tree with spatial splits).
    pub fn has_split_references(&self) -> bool {
        self.prim_order.len() > self.prim_count
    }

    /// Shape figures, including the key width the depth needs.
    pub fn stats(&self) -> TreeStats {
        self.stats
    }

    /// Number of nodes (internal and leaves).
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Never true: a tree has at least its root.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The key of every node (root 1, children `2k` and `2k+1`), by canonical index, widened to
    /// 64 bits.
    pub fn keys(&self) -> Vec<u64> {
        let mut keys = alloc::vec![0u64; self.nodes.len()];
        keys[0] = 1;
        for (i, n) in self.nodes.iter().enumerate() {
            if let NodeKind::Internal { left, right } = n.kind {
                keys[left as usize] = keys[i] << 1;
                keys[right as usize] = (keys[i] << 1) | 1;
            }
        }
        keys
    }

    /// The parent of every node by canonical index (`u32::MAX` for the root).
    pub fn parents(&self) -> Vec<u32> {
        let mut parents = alloc::vec![u32::MAX; self.nodes.len()];
        for (i, n) in self.nodes.iter().enumerate() {
            if let NodeKind::Internal { left, right } = n.kind {
                parents[left as usize] = i as u32;
                parents[right as usize] = i as u32;
            }
        }
        parents
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// A root over two leaves holding `left` and `right`.
    fn two_leaves(left: &[u32], right: &[u32]) -> (Vec<Bvh2Node>, Vec<u32>) {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let (l, r) = (left.len() as u32, right.len() as u32);
        let nodes = alloc::vec![
            Bvh2Node { bounds: b, kind: NodeKind::Internal { left: 1, right: 2 } },
            Bvh2Node { bounds: b, kind: NodeKind::Leaf { first: 0, count: l } },
            Bvh2Node { bounds: b, kind: NodeKind::Leaf { first: l, count: r } },
        ];
        (nodes, [left, right].concat())
    }

    #[test]
    fn split_references_are_admitted_only_where_asked_and_only_across_leaves() {
        let (nodes, order) = two_leaves(&[0, 1], &[1, 2]);
        let err = |e: Result<Bvh2, Error>| e.unwrap_err();
        assert_eq!(
            err(Bvh2::from_nodes(&nodes, 0, order.clone())),
            Error::MalformedTree("a primitive is referenced twice")
        );
        let split = Bvh2::from_split_nodes(&nodes, 0, order, 3).unwrap();
        assert!(split.has_split_references());
        assert_eq!((split.prim_count(), split.prim_order().len()), (3, 4));
        let (nodes, order) = two_leaves(&[0, 0], &[1, 2]);
        assert_eq!(
            err(Bvh2::from_split_nodes(&nodes, 0, order, 3)),
            Error::MalformedTree("a leaf references a primitive twice")
        );
        let (nodes, order) = two_leaves(&[0, 1], &[1, 0]);
        assert_eq!(
            err(Bvh2::from_split_nodes(&nodes, 0, order, 3)),
            Error::MalformedTree("some primitives are in no leaf")
        );
        let (nodes, order) = two_leaves(&[0, 1], &[2, 3]);
        let whole = Bvh2::from_nodes(&nodes, 0, order).unwrap();
        assert!(!whole.has_split_references());
        assert_eq!(whole.prim_count(), 4);
    }
}
