//! A conservative acceleration of the exact reference, for scenes too big for the brute force.
//!
//! [`ExactScene`] builds its own BVH (median splits; no code shared with the traversals under
//! test) whose boxes are the exact `f32` bounds of their triangles: `min`/`max` of `f32` values
//! round nothing, so the closed box holds every point of every triangle below it. A box is
//! skipped only where the exact ray provably does not meet it: the slab test is computed in `f64`
//! and every slab bound widened by more than its rounding error (below). Every triangle of every
//! box not skipped goes to [`closest_among`], which decides it exactly, so the answer is the
//! brute force's ([`super::closest_hit`]) exactly, `hits` included (no culling by `t`: the
//! verdict needs every triangle the ray hits).
//!
//! The bound: for a slab bound `b` and origin `o` (both `f32`, exact in `f64`) and a nonzero
//! direction component `d`, the computed `t = fl(fl(b - o) / d)` is `t_exact (1 + e1)(1 + e2)`
//! with `|e1|, |e2| <= 2^-53` (no underflow or overflow: `|b - o|` is 0 or at least `2^-149` and
//! at most `2^129`, `|d|` within `2^-149 .. 2^128`, so the quotient stays far inside `f64`'s
//! normal range). So `|t - t_exact| < 2^-51 |t|`, and widening by `2^-50 |t|` contains
//! `t_exact`. A zero component (of either sign) compares the origin with the slab exactly.

use super::closest::{closest_among, ExactAnswer};
use raytrail_core::geometry::Triangle;
use raytrail_core::Ray;

/// Widening of every slab bound, relative to its magnitude (see the module docs).
const SLACK: f64 = 1.0 / 1_125_899_906_842_624.0; // 2^-50

/// Most triangles in a leaf.
const LEAF: usize = 8;

/// One node: a leaf (`count > 0`: triangles `order[first..first + count]`) or an inner node
/// (children at `self + 1` and `first`).
#[derive(Clone, Copy, Debug)]
struct Node {
    min: [f32; 3],
    max: [f32; 3],
    first: u32,
    count: u32,
}

/// A scene prepared for exact closest-hit queries: the triangles and a conservative BVH over them.
#[derive(Clone, Debug)]
pub struct ExactScene {
    triangles: Vec<Triangle>,
    nodes: Vec<Node>,
    order: Vec<u32>,
}

impl ExactScene {
    /// Builds the culling BVH over `triangles` (primitive ids are indices).
    pub fn new(triangles: Vec<Triangle>) -> Self {
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF + 1);
        if !triangles.is_empty() {
            build(&triangles, &mut order, 0, &mut nodes);
        }
        Self { triangles, nodes, order }
    }

    /// The triangles.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// The exact answer for `ray`: the same as [`super::closest_hit`] over [`Self::triangles`].
    pub fn closest_hit(&self, ray: &Ray) -> ExactAnswer {
        if !ray.is_traceable() || self.nodes.is_empty() {
            return ExactAnswer::miss();
        }
        let o = ray.origin.map(f64::from);
        let d = ray.dir.map(f64::from);
        let (tmin, tmax) = (f64::from(ray.tmin), f64::from(ray.tmax));
        let mut candidates = Vec::new();
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i];
            if !may_meet(o, d, tmin, tmax, n) {
                continue;
            }
            if n.count > 0 {
                let (a, b) = (n.first as usize, (n.first + n.count) as usize);
                candidates.extend_from_slice(&self.order[a..b]);
            } else {
                stack.push(i + 1);
                stack.push(n.first as usize);
            }
        }
        candidates.sort_unstable();
        closest_among(ray, &self.triangles, candidates)
    }
}

/// Whether the exact ray may meet the closed box of `n` within `[tmin, tmax]` (never false where
/// it does: the module docs).
fn may_meet(o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64, n: &Node) -> bool {
    let (mut lo, mut hi) = (tmin, tmax);
    for k in 0..3 {
        let (bmin, bmax) = (f64::from(n.min[k]), f64::from(n.max[k]));
        if d[k] == 0.0 {
            if o[k] < bmin || o[k] > bmax {
                return false;
            }
            continue;
        }
        let a = (bmin - o[k]) / d[k];
        let b = (bmax - o[k]) / d[k];
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        lo = lo.max(a - a.abs() * SLACK);
        hi = hi.min(b + b.abs() * SLACK);
    }
    lo <= hi
}

/// The exact bounds of the triangles `ids`.
fn bounds(triangles: &[Triangle], ids: &[u32]) -> ([f32; 3], [f32; 3]) {
    let (mut min, mut max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for &id in ids {
        for v in &triangles[id as usize].v {
            for k in 0..3 {
                min[k] = min[k].min(v[k]);
                max[k] = max[k].max(v[k]);
            }
        }
    }
    (min, max)
}

/// Builds the subtree over `ids` (which start at `order` offset `first`) into `nodes`.
fn build(triangles: &[Triangle], ids: &mut [u32], first: usize, nodes: &mut Vec<Node>) {
    let (min, max) = bounds(triangles, ids);
    let me = nodes.len();
    nodes.push(Node { min, max, first: first as u32, count: ids.len() as u32 });
    if ids.len() <= LEAF {
        return;
    }
    // Median split of the centroids along the box's longest axis: any split is correct (the
    // boxes are exact whatever it is), this one keeps the depth logarithmic.
    let axis = (0..3).max_by(|&a, &b| (max[a] - min[a]).total_cmp(&(max[b] - min[b]))).unwrap_or(0);
    let key = |id: &u32| {
        let v = &triangles[*id as usize].v;
        v[0][axis] + v[1][axis] + v[2][axis]
    };
    let mid = ids.len() / 2;
    ids.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
    let (left, right) = ids.split_at_mut(mid);
    build(triangles, left, first, nodes);
    let right_node = nodes.len();
    build(triangles, right, first + mid, nodes);
    nodes[me].first = right_node as u32;
    nodes[me].count = 0;
}

#[cfg(test)]
mod tests {
    use super::super::closest_hit;
    use super::*;
    use crate::rng::Pcg32;
    use glam::Vec3;

    /// A grid of unit squares (two triangles each) at z = 0, with a second, smaller grid above.
    fn grid() -> Vec<Triangle> {
        let mut out = Vec::new();
        for (n, z, s) in [(12, 0.0f32, 1.0f32), (6, 0.75, 0.5)] {
            for i in 0..n {
                for j in 0..n {
                    let p = |a: usize, b: usize| Vec3::new((i + a) as f32 * s, (j + b) as f32 * s, z);
                    out.push(Triangle::new(p(0, 0), p(1, 0), p(1, 1)));
                    out.push(Triangle::new(p(0, 0), p(1, 1), p(0, 1)));
                }
            }
        }
        out
    }

    #[test]
    fn the_culled_answer_is_the_brute_force_answer() {
        let tris = grid();
        let scene = ExactScene::new(tris.clone());
        let mut rng = Pcg32::new(7, 1);
        let mut rays = Vec::new();
        for _ in 0..400 {
            let o = rng.in_box(Vec3::new(-2.0, -2.0, -2.0), Vec3::new(14.0, 14.0, 3.0));
            rays.push(Ray::new(o, rng.unit_vector(), 0.0, f32::INFINITY));
            // Aimed at a vertex or an edge point of the grids, exactly representable.
            let target = Vec3::new(rng.below(13) as f32, rng.below(26) as f32 * 0.5, 0.0);
            rays.push(Ray::new(o, target - o, 0.0, f32::INFINITY));
            rays.push(Ray::new(o, target - o, 0.0, 1.0));
        }
        // Axis-parallel rays with signed zeros, and one along a shared edge inside the plane.
        for dir in [Vec3::new(0.0, -0.0, -1.0), Vec3::new(-0.0, 0.0, 1.0), Vec3::X] {
            rays.push(Ray::new(Vec3::new(3.0, 4.0, 2.0), dir, 0.0, f32::INFINITY));
            rays.push(Ray::new(Vec3::new(3.0, 4.0, -0.0), dir, 0.0, f32::INFINITY));
        }
        let mut hits = 0;
        for r in &rays {
            let (fast, slow) = (scene.closest_hit(r), closest_hit(r, &tris));
            assert_eq!(fast, slow, "{r:?}");
            hits += usize::from(!slow.hits.is_empty());
        }
        // The test means something: many rays hit, some of them several triangles at one `t`.
        assert!(hits > 300, "{hits}");
        assert!(rays.iter().any(|r| scene.closest_hit(r).winners.len() > 1));
    }

    #[test]
    fn boxes_hold_their_triangles_and_touching_rays_are_kept() {
        let scene = ExactScene::new(grid());
        assert!(scene.nodes.len() > 10);
        // Every leaf's triangles lie in every box on its path: checked by walking down.
        fn check(s: &ExactScene, i: usize, outer: &[([f32; 3], [f32; 3])]) {
            let n = s.nodes[i];
            let mut path = outer.to_vec();
            path.push((n.min, n.max));
            if n.count > 0 {
                for &id in &s.order[n.first as usize..(n.first + n.count) as usize] {
                    for v in &s.triangles[id as usize].v {
                        for (lo, hi) in &path {
                            assert!((0..3).all(|k| lo[k] <= v[k] && v[k] <= hi[k]));
                        }
                    }
                }
            } else {
                check(s, i + 1, &path);
                check(s, n.first as usize, &path);
            }
        }
        check(&scene, 0, &[]);
        // A ray touching a box exactly at its corner, at a grazing slope, is not culled.
        let n = Node { min: [0.0; 3], max: [1.0; 3], first: 0, count: 1 };
        // From (-1, 1) towards (0, 0) the ray only touches the corner; a hair lower it misses.
        let o = [-1.0, 1.0, 0.5];
        assert!(may_meet(o, [1.0, -1.0, 0.0], 0.0, f64::INFINITY, &n));
        assert!(!may_meet(o, [0.999_999, -1.0, 0.0], 0.0, f64::INFINITY, &n));
        assert!(!may_meet(o, [1.0, -1.0, 0.0], 0.0, 0.999, &n));
        assert!(!may_meet([-1.0, 0.5, 2.0], [1.0, 0.0, -0.0], 0.0, f64::INFINITY, &n));
        assert!(ExactScene::new(Vec::new()).closest_hit(&Ray::new(Vec3::ZERO, Vec3::X, 0.0, 1.0)).hits.is_empty());
    }
}
