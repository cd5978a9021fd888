//! The 8-wide BVH stored level by level (Garanzha & Loop 2010, Sec. 3.3): each node holds its own
//! box and its children's block, the children of a node are consecutive, and the nodes of a level
//! are consecutive, so a breadth-first traversal reads each level as one sweep.

use crate::bvh2::NodeRef;
use crate::geometry::Triangle;
use crate::wide::{LeafBlock, WideBvh, WideChild, WideSliceMemory};
use crate::{Aabb, Error};
use alloc::vec;
use alloc::vec::Vec;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// A node of the level-order tree: 32 bytes, as the paper's (six floats of box, a word for the
/// children, a word for their spatial order).
///
/// | offset | field | internal node | leaf |
/// |---|---|---|---|
/// | 0 | `lo` | box | box |
/// | 12 | `first` | index of the first child | first triangle position |
/// | 16 | `hi` | box | box |
/// | 28 | `info` | bits 0-3: children (1-8); bits 8 + 3k..: child k's octant | bits 0-3: 0; bits 4..: triangles |
///
/// A child's octant says on which side of the node's center its own center lies, per axis (bit
/// `i`: above on axis `i`); the children are stored in ascending octant order (the paper's
/// "spatial 3D ascending order").
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct LevelNode {
    /// Lower box corner.
    pub lo: [f32; 3],
    /// First child, or first triangle position.
    pub first: u32,
    /// Upper box corner.
    pub hi: [f32; 3],
    /// Child count and octants, or triangle count (see the table).
    pub info: u32,
}

impl LevelNode {
    /// Children of an internal node; 0 for a leaf.
    #[inline(always)]
    pub fn children(&self) -> u32 {
        self.info & 0xf
    }

    /// Whether this is a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.children() == 0
    }

    /// A leaf's triangle count.
    #[inline(always)]
    pub fn triangles(&self) -> u32 {
        self.info >> 4
    }

    /// The octant of child `k` of an internal node.
    #[inline(always)]
    pub fn octant(&self, k: u32) -> u32 {
        (self.info >> (8 + 3 * k)) & 7
    }

    /// The box.
    #[inline(always)]
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (Vec3::from_array(self.lo), Vec3::from_array(self.hi))
    }
}

/// The level-order 8-wide tree with its triangles (those of the [`WideBvh`] it was laid out from:
/// leaves start at multiples of four, for block tests).
#[derive(Clone, Debug)]
pub struct LevelBvh {
    nodes: Vec<LevelNode>,
    level_starts: Vec<u32>,
    canonical: Vec<u32>,
    triangles: Vec<Triangle>,
    blocks: Vec<LeafBlock>,
    prims: Vec<u32>,
}

impl LevelBvh {
    /// Lays `tree` out level by level; `bounds` is the box of the whole scene (the root's).
    pub fn new(tree: &WideBvh<8>, bounds: &Aabb) -> Result<LevelBvh, Error> {
        let leaf_node = |lo: Vec3, hi: Vec3, first: u32, count: u32| -> Result<LevelNode, Error> {
            if count >= 1 << 28 {
                return Err(Error::TreeTooLarge { what: "a leaf's triangle count", size: count as usize });
            }
            Ok(LevelNode { lo: lo.to_array(), first, hi: hi.to_array(), info: count << 4 })
        };
        let root = tree.root();
        let mut nodes = vec![match root {
            WideChild::Leaf { first, count } => leaf_node(bounds.min, bounds.max, first, count)?,
            WideChild::Node(_) => LevelNode { lo: bounds.min.to_array(), first: 0, hi: bounds.max.to_array(), info: 0 },
        }];
        let mut wide = vec![root];
        let mut depth = vec![0u32];
        let mut i = 0;
        while i < nodes.len() {
            if let WideChild::Node(w) = wide[i] {
                let node = tree.nodes().get(w as usize).ok_or(Error::MalformedTree("a wide child names no node"))?;
                let center = (Vec3::from_array(nodes[i].lo) + Vec3::from_array(nodes[i].hi)) * 0.5;
                let mut children: Vec<(u32, usize)> = (0..8)
                    .filter(|&s| node.child_ref(s).is_some())
                    .map(|s| {
                        let (lo, hi) = node.child_box(s);
                        let c = (lo + hi) * 0.5;
                        (u32::from(c.x > center.x) | u32::from(c.y > center.y) << 1 | u32::from(c.z > center.z) << 2, s)
                    })
                    .collect();
                children.sort_unstable();
                if children.is_empty() {
                    return Err(Error::MalformedTree("a wide node without children"));
                }
                let first =
                    u32::try_from(nodes.len()).map_err(|_| Error::TreeTooLarge { what: "nodes", size: nodes.len() })?;
                let mut info = children.len() as u32;
                for (k, &(octant, slot)) in children.iter().enumerate() {
                    info |= octant << (8 + 3 * k);
                    let (lo, hi) = node.child_box(slot);
                    let child = node.child_ref(slot).ok_or(Error::MalformedTree("an empty child slot"))?;
                    nodes.push(match child {
                        WideChild::Leaf { first, count } => leaf_node(lo, hi, first, count)?,
                        WideChild::Node(_) => LevelNode { lo: lo.to_array(), first: 0, hi: hi.to_array(), info: 0 },
                    });
                    wide.push(child);
                    depth.push(depth[i] + 1);
                }
                nodes[i].first = first;
                nodes[i].info = info;
            }
            i += 1;
        }
        let mut level_starts: Vec<u32> =
            (0..nodes.len()).filter(|&i| i == 0 || depth[i] != depth[i - 1]).map(|i| i as u32).collect();
        level_starts.push(nodes.len() as u32);
        let canonical = wide.iter().map(|c| tree.canonical_id(c.node_ref()).unwrap_or(u32::MAX)).collect();
        Ok(LevelBvh {
            nodes,
            level_starts,
            canonical,
            triangles: tree.triangles().to_vec(),
            blocks: tree.blocks().to_vec(),
            prims: tree.prims().to_vec(),
        })
    }

    /// The nodes, root first, level by level.
    pub fn nodes(&self) -> &[LevelNode] {
        &self.nodes
    }

    /// Where each level starts in [`LevelBvh::nodes`], then the node count: level `l` is
    /// `level_starts[l]..level_starts[l + 1]`.
    pub fn level_starts(&self) -> &[u32] {
        &self.level_starts
    }

    /// Number of levels (a tree of one leaf has one).
    pub fn levels(&self) -> usize {
        self.level_starts.len() - 1
    }

    /// The canonical BVH2 id of node `index` (the binary node it stands for).
    pub fn canonical_id(&self, index: u32) -> u32 {
        self.canonical.get(index as usize).copied().unwrap_or(u32::MAX)
    }

    /// The reference an observer records for node `index`: a leaf by its first triangle (an
    /// index past the nodes is named as an internal node, which no recording matches).
    pub fn node_ref(&self, index: u32) -> NodeRef {
        match self.nodes.get(index as usize) {
            Some(n) if n.is_leaf() => NodeRef::leaf(n.first),
            _ => NodeRef::internal(index),
        }
    }

    /// The triangles as the wide traversal's leaf test reads them (no wide nodes: this tree's
    /// nodes are read directly).
    pub fn leaf_memory(&self) -> WideSliceMemory<'_, 8> {
        WideSliceMemory { nodes: &[], triangles: &self.triangles, blocks: &self.blocks }
    }

    /// Bytes of the nodes and triangle arrays.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * core::mem::size_of::<LevelNode>()
            + self.triangles.len() * core::mem::size_of::<Triangle>()
            + self.blocks.len() * core::mem::size_of::<LeafBlock>()
            + self.prims.len() * 4
    }

    /// The triangles in leaf order.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// The primitive id of each triangle position.
    pub fn prims(&self) -> &[u32] {
        &self.prims
    }
}
