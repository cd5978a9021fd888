//! Localized intersection (Garanzha & Loop 2010, Sec. 3.4, Fig. 10): each ray of a packet against
//! the leaves its packet's frustum reached, in their order, masked by each leaf's box: a leaf the
//! ray does not enter over its current interval (up to its closest hit so far) is skipped, so
//! leaves behind a hit cost one box test.

use super::levels::{LevelBvh, LevelNode};
use crate::intersect::{NoPair, TriangleTest};
use crate::method::Query;
use crate::observe::Observer;
use crate::traverse::begin;
use crate::wide::{ChildKernel, WideChild, WideNode};
use crate::{Hit, Ray};
use alloc::vec::Vec;

/// The near side of a leaf's box along `axis` (and whether the rays run toward its negative end).
fn near_side(n: &LevelNode, (a, negative): (usize, bool)) -> f32 {
    if negative {
        n.hi[a]
    } else {
        n.lo[a]
    }
}

/// The order [`intersect_packet`] visits `leaves` in: by the near side of each leaf's box along
/// the frustum's axis (`frustum_axis`: the axis and whether the rays run toward its negative end),
/// ties by list position; the list order where the frustum has no axis. Entries that name no leaf
/// of `tree` are left out.
pub fn visiting_order(tree: &LevelBvh, leaves: &[u32], frustum_axis: Option<(usize, bool)>) -> Vec<u32> {
    // Only leaves of the tree are visited: an index past the nodes, or of an internal node, is
    // dropped (only a damaged list has one).
    let leaves: Vec<u32> =
        leaves.iter().copied().filter(|&l| tree.nodes().get(l as usize).is_some_and(LevelNode::is_leaf)).collect();
    let Some(axis) = frustum_axis else { return leaves };
    // Sorted by (near side, list position), packed in a `u64` with the float's bits made to order
    // as integers: one sort of plain integers, no float comparisons.
    let ordered_bits = |x: f32| {
        let b = x.to_bits();
        if b >> 31 == 1 {
            !b
        } else {
            b | 1 << 31
        }
    };
    let mut keyed: Vec<u64> = leaves
        .iter()
        .enumerate()
        .map(|(i, &leaf)| {
            let n = near_side(&tree.nodes()[leaf as usize], axis);
            u64::from(ordered_bits(if axis.1 { -n } else { n })) << 32 | i as u64
        })
        .collect();
    keyed.sort_unstable();
    keyed.iter().map(|k| leaves[(k & 0xffff_ffff) as usize]).collect()
}

/// Traces `rays` (a packet's, in sorted order) against the leaves `leaves` (node indices, in
/// order) into `hits` (one per ray). Leaves are tested with the wide traversal's
/// leaf test, four triangles at a time where `K` says so, and report to `obs` as in the wide
/// traversal: a leaf entered, each triangle tested, each hit taken.
///
/// The leaf boxes are gathered into 8-wide nodes once per packet, and each ray tests eight boxes
/// at once with `K`'s child test over its interval at the start of the eight; a box is tested again
/// alone, over the shorter interval, where a hit in an earlier leaf of the eight has moved the
/// limit since. So a leaf is entered exactly when the one-at-a-time mask of Fig. 10 would enter it.
///
/// "Closest triangles first" (Sec. 3.4): where the frustum has a dominant axis (`frustum_axis`:
/// the axis and whether the rays run toward its negative end), the leaves are visited by their
/// near side along it, and a ray stops at the first leaf whose near-side distance alone already
/// exceeds what its slab test would accept: every later leaf's is at least as far. The answer is
/// the one the list order gives (the closest hit does not depend on the order; only the work does).
#[allow(clippy::too_many_arguments)]
pub fn intersect_packet<T: TriangleTest, K: ChildKernel, O: Observer>(
    tree: &LevelBvh,
    leaves: &[u32],
    frustum_axis: Option<(usize, bool)>,
    rays: &[Ray],
    scene_scale: f32,
    query: Query,
    hits: &mut [Hit],
    obs: &mut O,
) {
    let (nodes, mem) = (tree.nodes(), tree.leaf_memory());
    let order = visiting_order(tree, leaves, frustum_axis);
    let near = |leaf: u32, axis| near_side(&nodes[leaf as usize], axis);
    let firsts: Vec<f32> =
        frustum_axis.map_or_else(Vec::new, |axis| order.chunks(8).map(|run| near(run[0], axis)).collect());
    let boxes: Vec<WideNode<8>> = order
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
    for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
        let Some((ctx, mut q)) = begin::<T, NoPair>(ray, scene_scale, query) else {
            *hit = Hit::MISS;
            continue;
        };
        // Whether this ray runs the way the leaves are ordered (every ray that enters the scene
        // box does; one that does not misses every leaf anyway).
        let ordered = frustum_axis.filter(|&(a, negative)| ctx.slab.negative[a] == negative).map(|(a, _)| a);
        'leaves: for (b, block) in boxes.iter().enumerate() {
            let limit = q.limit();
            let (t0, t1) = ctx.box_interval(limit);
            if let Some(a) = ordered {
                // The slab test's near distance on this axis, as it computes it; beyond its
                // acceptance bound the slab test rejects this leaf and every later one.
                let tn = (firsts[b] - ctx.slab.origin[a]) * ctx.slab.inv_dir[a];
                if tn > t1 + ctx.slab.slack {
                    break;
                }
            }
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
        *hit = q.hit();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh2::SahBuilder;
    use crate::geometry::Triangle;
    use crate::intersect::Watertight;
    use crate::method::Collapse;
    use crate::observe::NoObserver;
    use crate::stream::frustum::Frustum;
    use crate::stream::traverse::expand_pair;
    use crate::wide::{ReferenceKernel, WideBvh};
    use crate::Aabb;
    use glam::Vec3;

    /// A damaged leaf list (an index past the nodes, an internal node) or node index is skipped,
    /// not a panic, and the valid leaves still give the hit.
    #[test]
    fn damaged_lists_are_skipped() {
        let tris: Vec<Triangle> = (0..40)
            .map(|i| {
                let x = i as f32;
                Triangle::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 0.0, 0.0), Vec3::new(x, 1.0, 0.0))
            })
            .collect();
        let bvh = SahBuilder::default().build(&tris).expect("build");
        let bounds = bvh.nodes()[0].bounds;
        let wide = WideBvh::<8>::build(&bvh, &tris, Collapse::PullUp).expect("collapse");
        let tree = LevelBvh::new(&wide, &bounds).expect("levels");
        let leaves: Vec<u32> = (0..tree.nodes().len() as u32).filter(|&i| tree.nodes()[i as usize].is_leaf()).collect();
        let damaged: Vec<u32> = [u32::MAX, 0].into_iter().chain(leaves.iter().copied()).collect();
        let ray = Ray::new(Vec3::new(3.25, 0.25, 5.0), Vec3::new(0.0, 0.0, -1.0), 0.0, f32::INFINITY);
        let mut hit = [Hit::MISS];
        intersect_packet::<Watertight, ReferenceKernel, _>(
            &tree,
            &damaged,
            Some((2, true)),
            core::slice::from_ref(&ray),
            Aabb::max_abs(&bounds),
            Query::Closest,
            &mut hit,
            &mut NoObserver,
        );
        assert!(hit[0].is_hit() && hit[0].t == 5.0, "{:?}", hit[0]);
        let mut out = [0u32; 8];
        let f = Frustum::build(core::slice::from_ref(&ray).iter(), &bounds, bounds.max_abs());
        assert_eq!(expand_pair::<crate::stream::FrustumCull>(tree.nodes(), &f, u32::MAX, &mut out), 0);
    }
}
