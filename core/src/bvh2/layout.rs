use super::tree::{Bvh2, NodeKind};
use super::{BinaryNode, LeafWord, NodeRef};
use crate::geometry::Triangle;
use crate::{Aabb, Error};
use alloc::vec::Vec;

/// What the link slots of a [`BinaryLayout`] hold (Binder & Keller 2016, Fig. 4 and 5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LinkKind {
    /// Internal nodes: uncle, grand uncle. Leaves: uncle, grand uncle, grand-grand uncle.
    Uncles,
    /// Internal nodes and leaves: parent, sibling (Áfra et al. 2014).
    ParentSibling,
}

/// The Aila-Laine layout of a canonical [`Bvh2`]: internal nodes with both child boxes, and leaf
/// triangle runs closed by a termination entry, with link references in the padding.
///
/// Internal nodes are numbered in canonical pre-order among internal nodes, leaves are laid out in
/// canonical pre-order, so both link kinds give every node the same address.
#[derive(Clone, Debug)]
pub struct BinaryLayout {
    /// Internal nodes.
    pub nodes: Vec<BinaryNode>,
    /// Leaf entries.
    pub leaves: Vec<LeafWord>,
    /// What the link slots hold.
    pub links: LinkKind,
    /// Reference of the root (a leaf for a one-leaf tree).
    pub root: NodeRef,
    /// Reference of each canonical node, by canonical index.
    pub refs: Vec<NodeRef>,
    /// Canonical index of each internal node, by layout index.
    internal_ids: Vec<u32>,
    /// Canonical index of each leaf, by leaf offset (`u32::MAX` at offsets inside a leaf).
    leaf_ids: Vec<u32>,
}

impl BinaryLayout {
    /// Lays out `bvh` over `triangles` (indexed by primitive id), with the given links.
    pub fn new(bvh: &Bvh2, triangles: &[Triangle], links: LinkKind) -> Result<BinaryLayout, Error> {
        let nodes = bvh.nodes();
        let mut refs = Vec::with_capacity(nodes.len());
        let (mut n_internal, mut leaf_words) = (0u32, 0usize);
        for n in nodes {
            match n.kind {
                NodeKind::Internal { .. } => {
                    refs.push(NodeRef::internal(n_internal));
                    n_internal += 1;
                }
                NodeKind::Leaf { count, .. } => {
                    if leaf_words >= NodeRef::LIMIT as usize {
                        return Err(Error::TreeTooLarge { what: "leaf array", size: leaf_words });
                    }
                    refs.push(NodeRef::leaf(leaf_words as u32));
                    leaf_words += 3 * count as usize + 1;
                }
            }
        }
        let parents = bvh.parents();
        let sibling = |i: usize| -> Option<usize> {
            let p = *parents.get(i)?;
            match nodes.get(p as usize)?.kind {
                NodeKind::Internal { left, right } => Some(if left as usize == i { right } else { left } as usize),
                NodeKind::Leaf { .. } => None,
            }
        };
        // Sibling of the ancestor `up` levels above node `i` (0: of `i` itself).
        let ancestor_sibling = |i: usize, up: u32| -> NodeRef {
            let mut a = i;
            for _ in 0..up {
                match parents[a] {
                    u32::MAX => return NodeRef::NONE,
                    p => a = p as usize,
                }
            }
            sibling(a).map_or(NodeRef::NONE, |s| refs[s])
        };
        let link_set = |i: usize| -> [NodeRef; 3] {
            match links {
                LinkKind::Uncles => [ancestor_sibling(i, 1), ancestor_sibling(i, 2), ancestor_sibling(i, 3)],
                LinkKind::ParentSibling => {
                    let p = parents[i];
                    [
                        if p == u32::MAX { NodeRef::NONE } else { refs[p as usize] },
                        ancestor_sibling(i, 0),
                        NodeRef::NONE,
                    ]
                }
            }
        };
        let mut out_nodes = Vec::with_capacity(n_internal as usize);
        let mut leaves = Vec::with_capacity(leaf_words);
        let mut internal_ids = Vec::with_capacity(n_internal as usize);
        let mut leaf_ids = alloc::vec![u32::MAX; leaf_words];
        for (i, n) in nodes.iter().enumerate() {
            let l = link_set(i);
            match n.kind {
                NodeKind::Internal { left, right } => {
                    let (a, b) = (nodes[left as usize].bounds, nodes[right as usize].bounds);
                    out_nodes.push(pack(a, b, [refs[left as usize], refs[right as usize]], [l[0], l[1]]));
                    internal_ids.push(i as u32);
                }
                NodeKind::Leaf { first, count } => {
                    leaf_ids[leaves.len()] = i as u32;
                    let prims = &bvh.prim_order()[first as usize..(first + count) as usize];
                    for (j, &p) in prims.iter().enumerate() {
                        let t = triangles
                            .get(p as usize)
                            .ok_or(Error::MalformedTree("primitive id beyond the triangles"))?;
                        // The free slots of the first triangle's second and third entries carry the
                        // first two links, so iterative backtracking can hop over a leaf without
                        // searching for its terminator (Binder & Keller 2016, Sec. 2.2, side note).
                        let (s1, s2) = if j == 0 { (l[0].0, l[1].0) } else { (0, 0) };
                        leaves.push(LeafWord::vertex_entry(t.v[0], p));
                        leaves.push(LeafWord::vertex_entry(t.v[1], s1));
                        leaves.push(LeafWord::vertex_entry(t.v[2], s2));
                    }
                    leaves.push(LeafWord::terminator(l));
                }
            }
        }
        let root = refs[0];
        Ok(BinaryLayout { nodes: out_nodes, leaves, links, root, refs, internal_ids, leaf_ids })
    }

    /// Canonical index of the node a reference points to.
    pub fn canonical_id(&self, r: NodeRef) -> Option<u32> {
        if r.is_leaf() {
            self.leaf_ids.get(r.offset() as usize).copied().filter(|&i| i != u32::MAX)
        } else {
            self.internal_ids.get(r.index() as usize).copied()
        }
    }

    /// Bytes of node and leaf data.
    pub fn bytes(&self) -> usize {
        core::mem::size_of_val(self.nodes.as_slice()) + core::mem::size_of_val(self.leaves.as_slice())
    }
}

fn pack(a: Aabb, b: Aabb, children: [NodeRef; 2], links: [NodeRef; 2]) -> BinaryNode {
    BinaryNode {
        left_xy: [a.min.x, a.max.x, a.min.y, a.max.y],
        right_xy: [b.min.x, b.max.x, b.min.y, b.max.y],
        z: [a.min.z, a.max.z, b.min.z, b.max.z],
        children,
        links,
    }
}
