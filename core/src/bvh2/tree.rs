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
    stats: TreeStats,
}

impl Bvh2 {
    /// Adopts nodes and a primitive order from a builder, renumbering them into canonical
    /// pre-order from `root`, and checks the structure: every node reached once, every primitive
    /// referenced once, depth at most 63, sizes within the 2^30 addresses of [`super::NodeRef`].
    pub fn from_nodes(nodes: &[Bvh2Node], root: u32, prim_order: Vec<u32>) -> Result<Bvh2, Error> {
        if nodes.is_empty() || prim_order.is_empty() {
            return Err(Error::EmptyScene);
        }
        let mut out: Vec<Bvh2Node> = Vec::with_capacity(nodes.len());
        let mut seen = alloc::vec![false; nodes.len()];
        let mut prim_seen = alloc::vec![false; prim_order.len()];
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
                        let s =
                            prim_seen.get_mut(p as usize).ok_or(Error::MalformedTree("primitive id out of range"))?;
                        if core::mem::replace(s, true) {
                            return Err(Error::MalformedTree("a primitive is referenced twice"));
                        }
                        new_order.push(p);
                    }
                    stats.leaves += 1;
                    stats.max_leaf_size = stats.max_leaf_size.max(count);
                    out.push(Bvh2Node { bounds: node.bounds, kind: NodeKind::Leaf { first: start, count } });
                }
            }
        }
        if new_order.len() != prim_order.len() {
            return Err(Error::MalformedTree("some primitives are in no leaf"));
        }
        if out.len() >= super::NodeRef::LIMIT as usize {
            return Err(Error::TreeTooLarge { what: "node count", size: out.len() });
        }
        stats.key_width = KeyWidth::for_depth(stats.depth).ok_or(Error::TreeTooDeep { depth: stats.depth, max: 63 })?;
        Ok(Bvh2 { nodes: out, prim_order: new_order, stats })
    }

    /// Checks that this tree bounds `triangles`: one primitive id per triangle, every leaf's box
    /// holding its triangles' boxes and every internal box its children's. A tree built for other
    /// triangles fails ([`Error::TreeMismatch`]); a tree that passes finds every hit, since no
    /// triangle lies outside the boxes a ray must enter to reach it. Linear in the tree's size.
    pub fn check_bounds(&self, triangles: &[Triangle]) -> Result<(), Error> {
        if self.prim_order.len() != triangles.len() {
            return Err(Error::TreeMismatch {
                node: 0,
                why: "its primitive count differs from the scene's triangle count",
            });
        }
        for (i, node) in self.nodes.iter().enumerate() {
            let fits = match node.kind {
                NodeKind::Internal { left, right } => [left, right]
                    .iter()
                    .all(|&c| self.nodes.get(c as usize).is_some_and(|child| node.bounds.contains(&child.bounds))),
                NodeKind::Leaf { first, count } => self.prim_order[first as usize..(first + count) as usize]
                    .iter()
                    .all(|&p| triangles.get(p as usize).is_some_and(|t| node.bounds.contains(&t.bounds()))),
            };
            if !fits {
                let why = match node.kind {
                    NodeKind::Internal { .. } => "its box does not hold a child's box",
                    NodeKind::Leaf { .. } => "its box does not hold one of its triangles",
                };
                return Err(Error::TreeMismatch { node: i, why });
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

    /// Primitive ids in leaf order.
    pub fn prim_order(&self) -> &[u32] {
        &self.prim_order
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
