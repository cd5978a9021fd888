//! The cheapest collapse of the binary tree into `W`-wide nodes under the surface-area heuristic,
//! by dynamic programming over the binary nodes (the collapse of Ylitie, Karras and Laine 2017,
//! without their leaf merging: every binary leaf stays whole, so enumerations still name
//! canonical leaves).
//!
//! With the leaves fixed, every cut pays the same for its leaves; what differs is which binary
//! nodes become wide nodes. A wide node standing for binary node `n` is visited by the rays that
//! enter `n`'s box, so its expected cost is proportional to `n`'s surface area, and the best
//! collapse is the one whose wide nodes have the least total area. Guthe's pull-up approximates
//! that top-down (open the largest child first); this finds the optimum. A subtree packed into
//! `i` slots is either one slot (itself: a leaf, or a wide node whose own `W` slots are packed
//! the same way) or the best split of the `i` slots between its two children.

use crate::bvh2::{Bvh2, NodeKind};
use alloc::vec::Vec;

/// For every binary node and every slot budget `1..=W`, how its subtree is best packed into at
/// most that many slots.
pub(super) struct OptimalCuts<const W: usize> {
    /// `split[n][i - 1]`: 0 where `n` packed into `i` slots is one slot (itself), else the slots
    /// its left child gets (the right gets the rest).
    split: Vec<[u8; W]>,
    /// `node_split[n]`: the left child's share of the `W` slots of a wide node at `n`.
    node_split: Vec<u8>,
}

impl<const W: usize> OptimalCuts<W> {
    /// Solves every subtree of `bvh` bottom-up. A wide node costs its half area; `leaf_cost(n)`
    /// is leaf `n`'s cost per unit of half area (the same in every cut).
    pub(super) fn solve(bvh: &Bvh2, leaf_cost: impl Fn(u32) -> f32) -> Self {
        let nodes = bvh.nodes();
        let mut cost = alloc::vec![[0.0f32; W]; nodes.len()];
        let mut split = alloc::vec![[0u8; W]; nodes.len()];
        let mut node_split = alloc::vec![0u8; nodes.len()];
        // Pre-order: children follow their parent, so a reverse sweep sees children first.
        for n in (0..nodes.len()).rev() {
            let area = nodes[n].bounds.half_area();
            let NodeKind::Internal { left, right } = nodes[n].kind else {
                cost[n] = [area * leaf_cost(n as u32); W];
                continue;
            };
            let (l, r) = (cost[left as usize], cost[right as usize]);
            // `dist[j - 1]`: the least cost of the two children sharing at most `j >= 2` slots.
            let mut dist = [f32::INFINITY; W];
            let mut share = [0u8; W];
            for j in 2..=W {
                for k in 1..j {
                    let c = l[k - 1] + r[j - k - 1];
                    if c < dist[j - 1] {
                        (dist[j - 1], share[j - 1]) = (c, k as u8);
                    }
                }
            }
            let own = area + dist[W - 1];
            // At least one slot each side, even where no cost compared (a NaN area): a wide node
            // never gets more than `W` slots.
            node_split[n] = share[W - 1].max(1);
            cost[n][0] = own;
            for i in 2..=W {
                // Ties keep the subtree whole: fewer slots for the same cost.
                (cost[n][i - 1], split[n][i - 1]) =
                    if dist[i - 1] < own { (dist[i - 1], share[i - 1]) } else { (own, 0) };
            }
        }
        Self { split, node_split }
    }

    /// The binary nodes that become the slots of the wide node at internal node `n`, in the
    /// binary tree's left-to-right order (none for a leaf).
    pub(super) fn slots(&self, bvh: &Bvh2, n: u32) -> Vec<u32> {
        let mut out = Vec::with_capacity(W);
        if let NodeKind::Internal { left, right } = bvh.nodes()[n as usize].kind {
            let k = self.node_split[n as usize] as usize;
            self.gather(bvh, left, k, &mut out);
            self.gather(bvh, right, W - k, &mut out);
        }
        out
    }

    /// Appends the slots of subtree `m` packed into at most `slots` (at least 1).
    fn gather(&self, bvh: &Bvh2, m: u32, slots: usize, out: &mut Vec<u32>) {
        let k = self.split[m as usize][slots.clamp(1, W) - 1] as usize;
        match bvh.nodes()[m as usize].kind {
            NodeKind::Internal { left, right } if k > 0 => {
                self.gather(bvh, left, k, out);
                self.gather(bvh, right, slots - k, out);
            }
            _ => out.push(m),
        }
    }
}
