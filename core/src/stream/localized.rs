//! Localized intersection (Garanzha & Loop 2010, Sec. 3.4, Fig. 10): each ray of a packet against
//! the leaves its packet's frustum reached, in their order, masked by each leaf's box: a leaf the
//! ray does not enter over its current interval (up to its closest hit so far) is skipped, so
//! leaves behind a hit cost one box test.

use super::levels::LevelBvh;
use crate::intersect::{NoPair, TriangleTest};
use crate::method::Query;
use crate::observe::Observer;
use crate::traverse::begin;
use crate::wide::ChildKernel;
use crate::{Hit, Ray};

/// Traces the rays `ids` (indices into `rays`) against the leaves `leaves` (node indices, in
/// order) into `hits` (one per id, in the same order). Leaves are tested with the wide traversal's
/// leaf test, four triangles at a time where `K` says so, and report to `obs` as in the wide
/// traversal: a leaf entered, each triangle tested, each hit taken.
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
    for (&id, hit) in ids.iter().zip(hits.iter_mut()) {
        let Some((ctx, mut q)) = begin::<T, NoPair>(&rays[id as usize], scene_scale, query) else {
            *hit = Hit::MISS;
            continue;
        };
        for &leaf in leaves {
            let node = &nodes[leaf as usize];
            let (lo, hi) = node.bounds();
            let (t0, t1) = ctx.box_interval(q.limit());
            // The mask of Fig. 10.
            if ctx.slab.hit(lo, hi, t0, t1).is_none() {
                continue;
            }
            obs.node(tree.node_ref(leaf));
            crate::wide::traverse::leaf::<8, _, T, K, O>(&mem, node.first, node.triangles(), &ctx, &mut q, obs);
            if q.is_answered() {
                break;
            }
        }
        *hit = q.hit;
    }
}
