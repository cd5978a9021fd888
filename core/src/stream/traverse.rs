//! Breadth-first frustum traversal (Garanzha & Loop 2010, Sec. 3.3, Fig. 9): a queue of (frustum,
//! node) pairs is expanded a level at a time. Each pair tests its node's children against its
//! frustum and counts the hits; an exclusive scan of the counts places each pair's hit children,
//! nearest side first, in the next queue. Leaves reached early are carried down unchanged (the
//! paper's "children of themselves"), so the final queue holds, per frustum, its leaves in order.

use super::exec::Parallel;
use super::frustum::{Frustum, FrustumTest};
use super::levels::LevelNode;
use super::scan::exclusive_scan;
use super::sort::compress;
use alloc::vec;
use alloc::vec::Vec;

/// A queue of (frustum, node) pairs, as two arrays.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PairQueue {
    /// Frustum of each pair.
    pub frustum: Vec<u32>,
    /// Node of each pair.
    pub node: Vec<u32>,
}

/// What the traversal leaves: every frustum's leaves in order, and the work it took.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LeafLists {
    /// The final queue: leaves (node indices), grouped by frustum in frustum order.
    pub pairs: PairQueue,
    /// Per frustum, the first position of its leaves in `pairs` and how many there are.
    pub ranges: Vec<[u32; 2]>,
    /// Queue length at the start of each level.
    pub queue_sizes: Vec<u32>,
    /// Frustum-box tests made.
    pub box_tests: u64,
}

/// The children of `node` that `frustum` overlaps, nearest side first (octant XOR the frustum's
/// direction signs, ties by storage order), as node indices in `out`; returns how many. A leaf is
/// its own single child.
#[inline]
pub fn expand_pair<F: FrustumTest>(nodes: &[LevelNode], frustum: &Frustum, node: u32, out: &mut [u32; 8]) -> u32 {
    let n = &nodes[node as usize];
    if n.is_leaf() {
        out[0] = node;
        return 1;
    }
    let mut keys = [0u32; 8];
    let mut count = 0;
    for k in 0..n.children() {
        let child = n.first + k;
        let (lo, hi) = nodes[child as usize].bounds();
        if F::overlaps(frustum, lo, hi) {
            // Key: the visiting rank in the high bits, the child's slot in the low ones.
            keys[count] = ((n.octant(k) ^ frustum.dir_signs) << 4) | k;
            count += 1;
        }
    }
    let keys = &mut keys[..count];
    keys.sort_unstable();
    for (o, key) in out.iter_mut().zip(keys.iter()) {
        *o = n.first + (key & 0xf);
    }
    count as u32
}

/// Traverses the level-order tree with every frustum, starting each with active rays at the root
/// (node 0), until only leaves remain; then compresses the final queue by frustum into ranges.
pub fn traverse<P: Parallel, F: FrustumTest>(exec: &P, nodes: &[LevelNode], frustums: &[Frustum]) -> LeafLists {
    let mut queue = PairQueue::default();
    for (f, fr) in frustums.iter().enumerate() {
        if fr.active > 0 && !nodes.is_empty() {
            queue.frustum.push(f as u32);
            queue.node.push(0);
        }
    }
    let mut out = LeafLists::default();
    while queue.node.iter().any(|&n| !nodes[n as usize].is_leaf()) {
        out.queue_sizes.push(queue.node.len() as u32);
        out.box_tests += queue.node.iter().map(|&n| u64::from(nodes[n as usize].children())).sum::<u64>();
        let expanded: Vec<(u32, [u32; 8])> = exec.map(queue.node.len(), |i| {
            let mut children = [0u32; 8];
            let f = queue.frustum[i];
            let count = expand_pair::<F>(nodes, &frustums[f as usize], queue.node[i], &mut children);
            (count, children)
        });
        let counts: Vec<u32> = expanded.iter().map(|e| e.0).collect();
        let (offsets, total) = exclusive_scan(&counts);
        let mut next = PairQueue { frustum: vec![0; total as usize], node: vec![0; total as usize] };
        for (i, (count, children)) in expanded.iter().enumerate() {
            let at = offsets[i] as usize;
            for (k, &child) in children.iter().take(*count as usize).enumerate() {
                next.frustum[at + k] = queue.frustum[i];
                next.node[at + k] = child;
            }
        }
        queue = next;
    }
    out.queue_sizes.push(queue.node.len() as u32);
    // The paper's compression of the final queue by frustum id.
    let chunks = compress(&queue.frustum);
    out.ranges = vec![[0, 0]; frustums.len()];
    for c in 0..chunks.len() {
        out.ranges[chunks.key[c] as usize] = [chunks.base[c], chunks.size[c]];
    }
    out.pairs = queue;
    out
}
