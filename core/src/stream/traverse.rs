//! Breadth-first frustum traversal (Garanzha & Loop 2010, Sec. 3.3, Fig. 9): a queue of (frustum,
//! node) pairs is expanded a level at a time. Each pair tests its node's children against its
//! frustum; its hit children, nearest side first, take its place in the next queue, in order (the
//! paper places them by an exclusive scan of the counts; see [`PAIRS_PER_ITEM`]). Leaves reached early are carried down unchanged (the
//! paper's "children of themselves"), so the final queue holds, per frustum, its leaves in order.

use super::exec::Parallel;
use super::frustum::{Frustum, FrustumTest};
use super::levels::LevelNode;
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
    // A node or child past the slice (only a damaged tree has one) expands to nothing.
    let Some(n) = nodes.get(node as usize) else { return 0 };
    if n.is_leaf() {
        out[0] = node;
        return 1;
    }
    let mut keys = [0u32; 8];
    let mut count = 0;
    for k in 0..n.children().min(8) {
        let child = n.first.wrapping_add(k);
        let Some(c) = nodes.get(child as usize) else { continue };
        let (lo, hi) = c.bounds();
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

/// Pairs expanded per work item: each item expands a run of consecutive pairs into its own output,
/// and the runs' outputs are concatenated in order. This is the scan-and-scatter of the paper with
/// the scan in two levels (within a run, then over the runs' sizes), which lets a CPU write each
/// run's output in one sweep instead of through a per-pair count array.
pub const PAIRS_PER_ITEM: usize = 2048;

/// One run's output: its pairs in order, whether any is an internal node, and its box tests.
struct Expanded {
    pairs: PairQueue,
    internal: bool,
    box_tests: u64,
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
    let mut internal = queue.node.iter().any(|&n| !nodes[n as usize].is_leaf());
    while internal {
        out.queue_sizes.push(queue.node.len() as u32);
        let runs = exec.map(queue.node.len().div_ceil(PAIRS_PER_ITEM), |r| {
            let range = r * PAIRS_PER_ITEM..((r + 1) * PAIRS_PER_ITEM).min(queue.node.len());
            let mut e = Expanded { pairs: PairQueue::default(), internal: false, box_tests: 0 };
            let mut children = [0u32; 8];
            for i in range {
                let f = queue.frustum[i];
                e.box_tests += u64::from(nodes[queue.node[i] as usize].children());
                let count = expand_pair::<F>(nodes, &frustums[f as usize], queue.node[i], &mut children);
                for &child in &children[..count as usize] {
                    e.internal |= !nodes[child as usize].is_leaf();
                    e.pairs.frustum.push(f);
                    e.pairs.node.push(child);
                }
            }
            e
        });
        let total = runs.iter().map(|e| e.pairs.node.len()).sum();
        let mut next = PairQueue { frustum: Vec::with_capacity(total), node: Vec::with_capacity(total) };
        internal = false;
        for e in runs {
            next.frustum.extend_from_slice(&e.pairs.frustum);
            next.node.extend_from_slice(&e.pairs.node);
            internal |= e.internal;
            out.box_tests += e.box_tests;
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
