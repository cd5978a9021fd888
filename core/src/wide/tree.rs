use super::leaf_block::LeafBlock;
use super::node::{WideChild, WideNode};
use super::optimal::OptimalCuts;
use crate::bvh2::{Bvh2, NodeKind, NodeRef};
use crate::geometry::Triangle;
use crate::intersect::BLOCK;
use crate::method::Collapse;
use crate::Error;
use alloc::vec::Vec;

/// Shape figures of a wide tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WideStats {
    /// Internal nodes.
    pub nodes: usize,
    /// Leaves (the binary tree's leaves, each kept whole).
    pub leaves: usize,
    /// Depth of the deepest leaf (a leaf child of the root: 1).
    pub depth: u32,
    /// Child slots left empty, over all nodes.
    pub empty_slots: usize,
    /// Bytes of the nodes.
    pub node_bytes: usize,
}

/// A `W`-wide BVH collapsed from a canonical BVH2 (Guthe 2014, Sec. 4.1), with its triangles in
/// leaf order. Every wide node stands for the binary node it was collapsed from, and every leaf is
/// a binary leaf with the same triangles, so enumerations name canonical BVH2 nodes.
///
/// Each leaf starts at a multiple of [`BLOCK`] in the triangle array (the gaps hold NaN triangles
/// that nothing hits, with primitive id `u32::MAX`), so its triangles are also whole
/// [`TriangleBlock`](crate::intersect::TriangleBlock)s, `first / BLOCK` onwards, for testing four at once.
#[derive(Clone, Debug)]
pub struct WideBvh<const W: usize> {
    nodes: Vec<WideNode<W>>,
    root: WideChild,
    triangles: Vec<Triangle>,
    blocks: Vec<LeafBlock>,
    prims: Vec<u32>,
    node_ids: Vec<u32>,
    leaf_ids: Vec<u32>,
    stats: WideStats,
}

impl<const W: usize> WideBvh<W> {
    /// Collapses `bvh` (over `triangles`, by primitive id) into a `W`-wide tree, `W` between 2
    /// and 32.
    pub fn build(bvh: &Bvh2, triangles: &[Triangle], collapse: Collapse) -> Result<WideBvh<W>, Error> {
        if !(2..=32).contains(&W) {
            return Err(Error::MalformedTree("a wide BVH has 2 to 32 children per node"));
        }
        let leaves_below = leaves_below(bvh);
        // A leaf of `n` triangles costs its blocks of four, as the SAH builder counts it.
        let leaf_blocks = |n: u32| match bvh.nodes()[n as usize].kind {
            NodeKind::Leaf { count, .. } => count.div_ceil(BLOCK as u32) as f32,
            NodeKind::Internal { .. } => 0.0,
        };
        let optimal = (collapse == Collapse::Optimal).then(|| OptimalCuts::solve(bvh, leaf_blocks));
        let mut b = Builder {
            bvh,
            scene: triangles,
            collapse,
            leaves_below,
            optimal,
            out: WideBvh {
                nodes: Vec::new(),
                root: WideChild::Node(0),
                triangles: Vec::with_capacity(bvh.prim_order().len() * 5 / 4),
                blocks: Vec::new(),
                prims: Vec::with_capacity(bvh.prim_order().len() * 5 / 4),
                node_ids: Vec::new(),
                leaf_ids: Vec::new(),
                stats: WideStats { nodes: 0, leaves: 0, depth: 0, empty_slots: 0, node_bytes: 0 },
            },
        };
        let root = b.child(0, 0)?;
        let mut out = b.out;
        out.root = root;
        out.blocks =
            out.triangles.chunks(BLOCK).zip(out.prims.chunks(BLOCK)).map(|(t, p)| LeafBlock::new(t, p)).collect();
        out.stats.nodes = out.nodes.len();
        out.stats.node_bytes = out.nodes.len() * core::mem::size_of::<WideNode<W>>();
        Ok(out)
    }

    /// The nodes to write, with the canonical ids of nodes and leaves, for [`WideBvh::refit`].
    pub(super) fn boxes_mut(&mut self) -> (&mut [WideNode<W>], &[u32], &[u32]) {
        (&mut self.nodes, &self.node_ids, &self.leaf_ids)
    }

    /// The canonical node ids of the inner children and of the leaves (by leaf position), for
    /// [`WideBvh::refit`]'s check.
    pub(super) fn canonical_ids(&self) -> (&[u32], &[u32]) {
        (&self.node_ids, &self.leaf_ids)
    }

    /// The triangles and blocks to write, with the primitive ids, for [`WideBvh::refit`].
    pub(super) fn triangles_mut(&mut self) -> (&mut [Triangle], &[u32], &mut [LeafBlock]) {
        (&mut self.triangles, &self.prims, &mut self.blocks)
    }

    /// The nodes, root first, in depth-first order.
    pub fn nodes(&self) -> &[WideNode<W>] {
        &self.nodes
    }

    /// Where traversal starts: node 0, or a leaf when the binary tree is a single leaf.
    pub fn root(&self) -> WideChild {
        self.root
    }

    /// The triangles in leaf order (a leaf's `first` indexes here).
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// The triangles in blocks of four with their primitive ids: block `i` holds positions
    /// `4 i .. 4 i + 3`.
    pub fn blocks(&self) -> &[LeafBlock] {
        &self.blocks
    }

    /// The tree as [`WideMemory`](super::WideMemory) for traversal in place.
    pub fn memory(&self) -> super::WideSliceMemory<'_, W> {
        super::WideSliceMemory { nodes: &self.nodes, triangles: &self.triangles, blocks: &self.blocks }
    }

    /// The primitive id of each triangle position (`u32::MAX` in the gaps between leaves).
    pub fn prims(&self) -> &[u32] {
        &self.prims
    }

    /// Shape figures.
    pub fn stats(&self) -> WideStats {
        self.stats
    }

    /// Bytes of everything the traversal reads or reports from: nodes, triangles in leaf order,
    /// their blocks of four with their ids, primitive ids by position (as the GPU and the embedded
    /// tables read them) and the canonical ids of nodes and leaves.
    pub fn bytes(&self) -> usize {
        core::mem::size_of_val(self.nodes.as_slice())
            + core::mem::size_of_val(self.triangles.as_slice())
            + core::mem::size_of_val(self.blocks.as_slice())
            + core::mem::size_of_val(self.prims.as_slice())
            + core::mem::size_of_val(self.node_ids.as_slice())
            + core::mem::size_of_val(self.leaf_ids.as_slice())
    }

    /// The canonical BVH2 id of a recorded reference ([`WideChild::node_ref`]), if it names a node
    /// or leaf of this tree.
    pub fn canonical_id(&self, r: NodeRef) -> Option<u32> {
        canonical_of(&self.node_ids, &self.leaf_ids, r)
    }
}

/// [`WideBvh::canonical_id`] from the id arrays alone ([`WideBvh::canonical_ids`]), for a pass
/// that writes the nodes while it reads them.
pub(super) fn canonical_of(node_ids: &[u32], leaf_ids: &[u32], r: NodeRef) -> Option<u32> {
    let id = if r.is_leaf() { *leaf_ids.get(r.offset() as usize)? } else { *node_ids.get(r.index() as usize)? };
    (id != u32::MAX).then_some(id)
}

/// A wide tree of either width: what a prepared scene lends a wide method, so that one match
/// picks the width a traversal is monomorphized for.
#[derive(Clone, Copy, Debug)]
pub enum WideTree<'a> {
    /// Four children per node.
    Four(&'a WideBvh<4>),
    /// Eight children per node.
    Eight(&'a WideBvh<8>),
}

impl WideTree<'_> {
    /// Where traversal starts.
    pub fn root(&self) -> WideChild {
        match self {
            WideTree::Four(t) => t.root(),
            WideTree::Eight(t) => t.root(),
        }
    }

    /// Shape figures.
    pub fn stats(&self) -> WideStats {
        match self {
            WideTree::Four(t) => t.stats(),
            WideTree::Eight(t) => t.stats(),
        }
    }

    /// The canonical BVH2 id of a recorded reference ([`WideBvh::canonical_id`]).
    pub fn canonical_id(&self, r: NodeRef) -> Option<u32> {
        match self {
            WideTree::Four(t) => t.canonical_id(r),
            WideTree::Eight(t) => t.canonical_id(r),
        }
    }
}

/// Leaves below each canonical node.
fn leaves_below(bvh: &Bvh2) -> Vec<u32> {
    let nodes = bvh.nodes();
    let mut below = alloc::vec![0u32; nodes.len()];
    // Pre-order: children follow their parent, so a reverse sweep sees children first.
    for i in (0..nodes.len()).rev() {
        below[i] = match nodes[i].kind {
            NodeKind::Leaf { .. } => 1,
            NodeKind::Internal { left, right } => below[left as usize] + below[right as usize],
        };
    }
    below
}

struct Builder<'a, const W: usize> {
    bvh: &'a Bvh2,
    scene: &'a [Triangle],
    collapse: Collapse,
    leaves_below: Vec<u32>,
    /// The solved cuts, for [`Collapse::Optimal`].
    optimal: Option<OptimalCuts<W>>,
    out: WideBvh<W>,
}

impl<const W: usize> Builder<'_, W> {
    /// The wide child standing for canonical node `n` at wide depth `depth`, building its subtree.
    fn child(&mut self, n: u32, depth: u32) -> Result<WideChild, Error> {
        let node = self.bvh.nodes()[n as usize];
        match node.kind {
            NodeKind::Leaf { first, count } => {
                let at = self.out.triangles.len();
                let start =
                    u32::try_from(at).map_err(|_| Error::TreeTooLarge { what: "triangle positions", size: at })?;
                for &p in &self.bvh.prim_order()[first as usize..(first + count) as usize] {
                    let tri = self.scene.get(p as usize).ok_or(Error::MalformedTree("primitive id out of range"))?;
                    self.out.triangles.push(*tri);
                    self.out.prims.push(p);
                }
                // The next leaf starts on a block boundary.
                let gap = self.out.triangles.len().next_multiple_of(BLOCK) - self.out.triangles.len();
                let nan = Triangle { v: [glam::Vec3::NAN; 3] };
                self.out.triangles.extend(core::iter::repeat_n(nan, gap));
                self.out.prims.extend(core::iter::repeat_n(u32::MAX, gap));
                self.out.leaf_ids.resize(self.out.triangles.len(), u32::MAX);
                self.out.leaf_ids[at] = n;
                self.out.stats.leaves += 1;
                self.out.stats.depth = self.out.stats.depth.max(depth);
                Ok(WideChild::Leaf { first: start, count })
            }
            NodeKind::Internal { .. } => {
                let index = u32::try_from(self.out.nodes.len())
                    .ok()
                    .filter(|&i| i < NodeRef::LIMIT)
                    .ok_or(Error::TreeTooLarge { what: "wide nodes", size: self.out.nodes.len() })?;
                self.out.nodes.push(WideNode::EMPTY);
                self.out.node_ids.push(n);
                let slots = self.slots(n);
                self.out.stats.empty_slots += W - slots.len();
                for (i, &c) in slots.iter().enumerate() {
                    let b = self.bvh.nodes()[c as usize].bounds;
                    let child = self.child(c, depth + 1)?;
                    self.out.nodes[index as usize].set_child(i, b.min, b.max, child);
                }
                Ok(WideChild::Node(index))
            }
        }
    }

    /// The canonical nodes that become the children of internal node `n`, in slot order: largest
    /// box first (ties in the binary tree's left-to-right order).
    ///
    /// Any-hit queries visit hit children in slot order (Guthe's unsorted occlusion), and the
    /// surface-area heuristic's estimate of the chance that a ray through a node enters a child
    /// is the child's box area: the largest box is the likeliest to hold an occluder. Against the
    /// binary tree's order this cut bvh8's nodes per shadow ray by 5-60% and made shadow rays
    /// 1.08-1.70 times as fast (`docs/notes/*-benchmarks-one-loop.md`, "Children largest box first").
    /// Closest-hit queries sort by entry distance and meet the slot order only in ties.
    fn slots(&self, n: u32) -> Vec<u32> {
        let mut c = self.slots_in_tree_order(n);
        // Stable, so equal areas keep the tree's order; areas are finite, so the order is total.
        c.sort_by(|&a, &b| self.area(b).total_cmp(&self.area(a)));
        c
    }

    /// [`Builder::slots`] before ordering: the binary tree's left-to-right order.
    fn slots_in_tree_order(&self, n: u32) -> Vec<u32> {
        let mut c = self.children(n).map_or_else(Vec::new, |(l, r)| alloc::vec![l, r]);
        match self.collapse {
            Collapse::EverySecondLevel => loop {
                let next: Vec<u32> = c
                    .iter()
                    .flat_map(|&x| self.children(x).map_or([x, u32::MAX], |(l, r)| [l, r]))
                    .filter(|&x| x != u32::MAX)
                    .collect();
                if next.len() > W || next.len() == c.len() {
                    return c;
                }
                c = next;
            },
            Collapse::Optimal => self.optimal.as_ref().map_or(c, |cuts| cuts.slots(self.bvh, n)),
            Collapse::PullUp => {
                let mut pulled = 0;
                while c.len() < W {
                    let Some(at) = self.pick(&c, pulled) else { break };
                    // `pick` only returns internal children.
                    let Some((l, r)) = self.children(c[at]) else { break };
                    c.splice(at..=at, [l, r]);
                    pulled += 1;
                }
                c
            }
        }
    }

    /// Which of the current children to pull up next (Guthe 2014, Sec. 4.1): a child with two
    /// leaves first (pulling it up removes a node), the largest box among them; else a child with
    /// three leaves if nothing was pulled up yet, or if it is the only internal child; else the
    /// internal child with the largest box. Ties go to the leftmost.
    fn pick(&self, c: &[u32], pulled: usize) -> Option<usize> {
        let internal: Vec<usize> = (0..c.len()).filter(|&i| self.children(c[i]).is_some()).collect();
        let largest = |among: &mut dyn Iterator<Item = usize>| -> Option<usize> {
            among.fold(None, |best: Option<usize>, i| match best {
                Some(b) if self.area(c[b]) >= self.area(c[i]) => Some(b),
                _ => Some(i),
            })
        };
        let below = |i: usize| self.leaves_below[c[i] as usize];
        if let Some(i) = largest(&mut internal.iter().copied().filter(|&i| below(i) == 2)) {
            return Some(i);
        }
        let three_ok = pulled == 0 || internal.len() == 1;
        if three_ok {
            if let Some(i) = largest(&mut internal.iter().copied().filter(|&i| below(i) == 3)) {
                return Some(i);
            }
        }
        largest(&mut internal.iter().copied().filter(|&i| below(i) != 3))
    }

    fn children(&self, n: u32) -> Option<(u32, u32)> {
        match self.bvh.nodes()[n as usize].kind {
            NodeKind::Internal { left, right } => Some((left, right)),
            NodeKind::Leaf { .. } => None,
        }
    }

    fn area(&self, n: u32) -> f32 {
        self.bvh.nodes()[n as usize].bounds.half_area()
    }
}
