//! The nearest-point walk of a wide tree: children visited nearest box first, a box farther than
//! the best distance so far (or the search radius) never entered.

use super::triangle::closest_point_on_triangle;
use super::NearestPoint;
use crate::prepared::normalize::scale_pow2;
use crate::prepared::PreparedScene;
use crate::wide::traverse::WideRoot;
use crate::wide::{WideChild, WideMemory, WideNode, WideTree};
use crate::Error;
use alloc::vec::Vec;
use glam::Vec3;

/// The squared distance from `p` to child `slot`'s box of `node` (0 inside it).
#[inline(always)]
fn box_distance2<const W: usize>(node: &WideNode<W>, slot: usize, p: Vec3) -> f32 {
    let (lo, hi) = node.child_box(slot);
    let d = (lo - p).max(p - hi).max(Vec3::ZERO);
    d.length_squared()
}

/// The point of the mesh in a `W`-wide tree nearest to `p` within distance `radius`
/// (inclusive), in the tree's frame; `None` when no triangle comes that close. `stack` is
/// scratch space, reused across queries.
pub fn nearest_point_in<const W: usize, M: WideMemory<W> + ?Sized>(
    mem: &M,
    root: WideRoot,
    p: Vec3,
    radius: f32,
    stack: &mut Vec<(WideChild, f32)>,
) -> Option<NearestPoint> {
    // Squared distance a candidate must not exceed: the radius, then the best so far.
    let mut bound = query_bound(p, radius)?;
    let mut best: Option<NearestPoint> = None;
    stack.clear();
    stack.push((root.root, 0.0));
    let mut budget = root.max_steps;
    while let Some((child, d2)) = stack.pop() {
        if d2 > bound {
            continue;
        }
        if budget == 0 {
            break;
        }
        budget -= 1;
        match child {
            WideChild::Node(index) => {
                let node = mem.wide_node(index);
                let mut near: [(f32, usize); W] = [(f32::INFINITY, 0); W];
                let mut n = 0;
                for slot in 0..W {
                    if node.child_ref(slot).is_some() {
                        let d = box_distance2(&node, slot, p);
                        if d <= bound {
                            near[n] = (d, slot);
                            n += 1;
                        }
                    }
                }
                // Farthest pushed first, so the nearest is popped next.
                near[..n].sort_unstable_by(|x, y| y.0.total_cmp(&x.0));
                for &(d, slot) in &near[..n] {
                    if let Some(c) = node.child_ref(slot) {
                        stack.push((c, d));
                    }
                }
            }
            WideChild::Leaf { first, count } => {
                for pos in first..first + count {
                    let tri = mem.wide_triangle(pos);
                    let on = closest_point_on_triangle(p, tri[0], tri[1], tri[2]);
                    let prim = mem.prim(pos);
                    let better = match &best {
                        None => on.distance2 <= bound,
                        Some(b) => on.distance2 < bound || (on.distance2 == bound && prim < b.prim),
                    };
                    if better {
                        bound = on.distance2;
                        best = Some(NearestPoint {
                            prim,
                            u: on.u,
                            v: on.v,
                            point: on.point.to_array(),
                            distance: on.distance2,
                        });
                    }
                }
            }
        }
    }
    // `distance` held the squared distance while searching.
    best.map(|b| NearestPoint { distance: libm::sqrtf(b.distance), ..b })
}

/// The point of `scene`'s mesh nearest to `p` within `radius` ([`nearest_point_in`] on the
/// scene's wide tree, [`PreparedScene::query_tree`]), with `p`, the point and the distance in the caller's
/// frame (the scene's power-of-two scale undone). `None` for a point that is not finite or has
/// no triangle within the radius.
pub fn nearest_point(
    scene: &PreparedScene,
    tree: (WideTree<'_>, WideRoot),
    p: [f32; 3],
    radius: f32,
    stack: &mut Vec<(WideChild, f32)>,
) -> Option<NearestPoint> {
    let (scaled, r) = framed_query(scene, p, radius);
    let (tree, root) = tree;
    let found = match tree {
        WideTree::Four(t) => nearest_point_in::<4, _>(&t.memory(), root, scaled, r, stack),
        WideTree::Eight(t) => nearest_point_in::<8, _>(&t.memory(), root, scaled, r, stack),
    }?;
    Some(unframed(scene, found))
}

/// A query point and search radius in `scene`'s frame (the scene's power-of-two scale applied),
/// as [`nearest_point_in`] takes them: what every backend's walk is handed.
pub fn framed_query(scene: &PreparedScene, p: [f32; 3], radius: f32) -> (Vec3, f32) {
    let k = scene.exponent;
    (Vec3::from_array(p.map(|x| scale_pow2(x, -k))), scale_pow2(radius, -k))
}

/// The squared distance a point must not exceed for a query in the scene's frame
/// ([`framed_query`]), as [`nearest_point_in`] starts from it; `None` where that walk answers
/// `None` before visiting a node (a point that is not finite, a radius that is negative or NaN).
pub fn query_bound(p: Vec3, radius: f32) -> Option<f32> {
    (p.is_finite() && !radius.is_nan() && radius >= 0.0).then_some(radius * radius)
}

/// A nearest point found in `scene`'s frame, with its distance, back in the caller's frame.
pub fn unframed(scene: &PreparedScene, found: NearestPoint) -> NearestPoint {
    let k = scene.exponent;
    NearestPoint { point: found.point.map(|x| scale_pow2(x, k)), distance: scale_pow2(found.distance, k), ..found }
}

/// [`nearest_point`] of each of `points`, one after another on this thread (a backend splits a
/// batch into chunks). [`Error::NotPrepared`] for a scene without a wide tree.
pub fn nearest_points(
    scene: &PreparedScene,
    points: &[[f32; 3]],
    radius: f32,
) -> Result<Vec<Option<NearestPoint>>, Error> {
    let tree = scene.query_tree()?;
    let mut stack = Vec::new();
    Ok(points.iter().map(|&p| nearest_point(scene, tree, p, radius, &mut stack)).collect())
}
