//! Localized intersection (Garanzha & Loop 2010, Sec. 3.4, Fig. 10): each ray of a packet against
//! the leaves its packet's frustum reached, in their order, masked by each leaf's box: a leaf the
//! ray does not enter over its current interval (up to its closest hit so far) is skipped, so
//! leaves behind a hit cost one box test.

use super::levels::LevelBvh;
use crate::intersect::{NoPair, TriangleTest};
use crate::method::Query;
use crate::observe::Observer;
use crate::traverse::begin;
use crate::wide::{ChildKernel, WideChild, WideNode};
use alloc::vec::Vec;
use crate::{Hit, Ray};

/// Traces the rays `ids` (indices into `rays`) against the leaves `leaves` (node indices, in
/// order) into `hits` (one per id, in the same order). Leaves are tested with the wide traversal's
/// leaf test, four triangles at a time where `K` says so, and report to `obs` as in the wide
/// traversal: a leaf entered, each triangle tested, each hit taken.
///
/// The leaf boxes are gathered into 8-wide nodes once per packet, and each ray tests eight boxes
/// at once with `K`'s child test over its interval at the start of the eight; a box is tested again
/// alone, over the shorter interval, where a hit in an earlier leaf of the eight has moved the
/// limit since. So a leaf is entered exactly when the one-at-a-time mask of Fig. 10 would enter it.
#[allow(clippy::too_many_arguments)]
pub fn intersect_packet<T: TriangleTest, K: ChildKernel, O: Observer>(
    tree: &LevelBvh,
    leaves: &[u32],
    rays: &[Ray],
    ids: &[u32],
    scene_scale: f32,
    query: Query,
    hits: &mut [Hit],
    obs: &mut O,
) {
    let (nodes, mem) = (tree.nodes(), tree.leaf_memory());
    let boxes: Vec<WideNode<8>> = leaves
        .chunks(8)
        .map(|run| {
            let mut n = WideNode::EMPTY;
            for (i, &leaf) in run.iter().enumerate() {
                let (lo, hi) = nodes[leaf as usize].bounds();
                n.set_child(i, lo, hi, WideChild::Node(leaf));
            }
            n
        })
        .collect();
    for (&id, hit) in ids.iter().zip(hits.iter_mut()) {
        let Some((ctx, mut q)) = begin::<T, NoPair>(&rays[id as usize], scene_scale, query) else {
            *hit = Hit::MISS;
            continue;
        };
        'leaves: for block in &boxes {
            let limit = q.limit();
            let (t0, t1) = ctx.box_interval(limit);
            let mut mask = K::test::<8>(block, &ctx.slab, t0, t1).mask;
            while mask != 0 {
                let slot = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let leaf = block.child[slot];
                let node = &nodes[leaf as usize];
                if q.limit().to_bits() != limit.to_bits() {
                    let (lo, hi) = node.bounds();
                    let (t0, t1) = ctx.box_interval(q.limit());
                    if ctx.slab.hit(lo, hi, t0, t1).is_none() {
                        continue;
                    }
                }
                obs.node(tree.node_ref(leaf));
                crate::wide::traverse::leaf::<8, _, T, K, O>(&mem, node.first, node.triangles(), &ctx, &mut q, obs);
                if q.is_answered() {
                    break 'leaves;
                }
            }
        }
        *hit = q.hit;
    }
}
