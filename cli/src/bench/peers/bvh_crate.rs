//! The `bvh` crate 0.13: its binned-SAH BVH (one triangle per leaf, built in parallel with
//! `build_par`), its iterators and its own ray/triangle test.
//!
//! The crate has no closest-hit traversal; it yields the shapes whose boxes a ray enters. Closest
//! hits use its `nearest_traverse_iterator`, which yields leaves in increasing entry distance (a
//! heap over nodes), and stop at the first leaf that starts beyond the closest hit so far: the
//! fastest use of its API we found (its plain iterator, which visits every box the ray crosses,
//! traced Sponza's primary rays at half the speed). Any hits use its allocation-free stack
//! iterator and stop at the first hit; that iterator's stack has 32 entries, so for deeper trees
//! the heap iterator serves any hits too.
//!
//! The crate's own hit rule: its ray has no interval (`tmin`/`tmax` are checked on the returned
//! distance here) and its direction is normalized, so distances are converted back to raytrail's
//! `t` by dividing by the direction's length (which rounds). Its triangle test is Möller-Trumbore
//! with backface culling and an absolute epsilon (`f32::EPSILON`) on the determinant, so it also
//! rejects triangles whose area across the ray is below that: many of the dragon's.

use super::PeerTree;
use crate::bench::report::Built;
use crate::bench::target::Work;
use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::{BHShape, BoundingHierarchy};
use bvh::bvh::{Bvh, BvhNode};
use bvh::ray::Ray as BvhRay;
use glam::Vec3;
use nalgebra::{Point3, Vector3};
use raytrail::core::intersect::{TriangleTest, Watertight};
use raytrail::core::scene::Scene;
use raytrail::core::{Hit, Ray};
use std::time::Instant;

/// Deepest tree (root at depth 0) the crate's stack iterator can walk without overflowing.
const STACK_ITERATOR_DEPTH: usize = 30;

/// A triangle as the crate stores shapes: vertices, box, raytrail primitive id, node backlink.
#[derive(Clone, Debug)]
pub struct BvhTriangle {
    v: [Point3<f32>; 3],
    aabb: Aabb<f32, 3>,
    prim: u32,
    node: usize,
}

impl Bounded<f32, 3> for BvhTriangle {
    fn aabb(&self) -> Aabb<f32, 3> {
        self.aabb
    }
}

impl BHShape<f32, 3> for BvhTriangle {
    fn set_bh_node_index(&mut self, index: usize) {
        self.node = index;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// The crate's BVH over a scene.
pub struct BvhScene {
    bvh: Bvh<f32, 3>,
    shapes: Vec<BvhTriangle>,
    /// Whether the stack iterator is safe on this tree.
    shallow: bool,
}

impl BvhScene {
    /// Builds the crate's BVH over `scene` (in parallel on the current rayon pool).
    pub fn new(scene: &Scene) -> (Self, Built) {
        let p = |v: Vec3| Point3::new(v.x, v.y, v.z);
        let mut shapes: Vec<BvhTriangle> = scene
            .triangles()
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let b = t.bounds();
                BvhTriangle {
                    v: [p(t.v[0]), p(t.v[1]), p(t.v[2])],
                    aabb: Aabb::with_bounds(p(b.min), p(b.max)),
                    prim: i as u32,
                    node: 0,
                }
            })
            .collect();
        let start = Instant::now();
        let bvh = Bvh::build_par(&mut shapes);
        let seconds = start.elapsed().as_secs_f64();
        let shallow = depth(&bvh) <= STACK_ITERATOR_DEPTH;
        let bytes = vec![
            ("nodes".to_string(), std::mem::size_of_val(bvh.nodes.as_slice())),
            ("shapes (triangles, boxes)".to_string(), std::mem::size_of_val(shapes.as_slice())),
        ];
        (Self { bvh, shapes, shallow }, Built { what: "bvh (binned SAH, build_par)".to_string(), seconds, bytes })
    }
}

/// Depth of the crate's tree (root 0).
fn depth(bvh: &Bvh<f32, 3>) -> usize {
    let mut deepest = 0;
    let mut todo = vec![(0usize, 0usize)];
    while let Some((i, d)) = todo.pop() {
        deepest = deepest.max(d);
        if let Some(BvhNode::Node { child_l_index, child_r_index, .. }) = bvh.nodes.get(i) {
            todo.push((*child_l_index, d + 1));
            todo.push((*child_r_index, d + 1));
        }
    }
    deepest
}

impl PeerTree for BvhScene {
    /// Closest hit of one ray and the triangle tests made (counted when `COUNT`).
    #[inline(always)]
    fn closest<const WT: bool, const COUNT: bool>(&self, ray: &Ray) -> (Hit, u64) {
        let s = self;
        let (br, len) = bvh_ray(ray);
        let sheared = WT.then(|| Watertight::prepare(ray));
        let (mut best, mut tests) = (Hit::MISS, 0u64);
        // The closest hit so far in the crate's distance units (the ray's end before any hit).
        let mut limit = ray.tmax * len;
        for tri in s.bvh.nearest_traverse_iterator(&br, &s.shapes) {
            if br.intersection_slice_for_aabb(&tri.aabb).is_some_and(|(entry, _)| entry > limit) {
                break;
            }
            tests += u64::from(COUNT);
            match &sheared {
                Some(sh) => {
                    let [a, b, c] = tri.v.map(|p| Vec3::new(p.x, p.y, p.z));
                    if let Some(h) = Watertight::intersect(sh, a, b, c, ray.tmin, best.t.min(ray.tmax)) {
                        if best.is_beaten_by(h.t, tri.prim) {
                            best = Hit { t: h.t, prim: tri.prim, u: h.u, v: h.v };
                            // Padded so that rounding never cuts off a leaf holding a tie.
                            limit = h.t * len * (1.0 + 8.0 * f32::EPSILON);
                        }
                    }
                }
                None => {
                    let x = br.intersects_triangle(&tri.v[0], &tri.v[1], &tri.v[2]);
                    let t = x.distance / len;
                    if t >= ray.tmin && t <= ray.tmax && t < best.t {
                        best = Hit { t, prim: tri.prim, u: x.u, v: x.v };
                        limit = x.distance;
                    }
                }
            }
        }
        (best, tests)
    }

    /// Any hit of one ray and the triangle tests made (counted when `COUNT`).
    #[inline(always)]
    fn any<const WT: bool, const COUNT: bool>(&self, ray: &Ray) -> (Hit, u64) {
        let s = self;
        let (br, _) = bvh_ray(ray);
        if s.shallow {
            first_hit::<WT, COUNT>(ray, &br, s.bvh.traverse_iterator(&br, &s.shapes))
        } else {
            first_hit::<WT, COUNT>(ray, &br, s.bvh.nearest_traverse_iterator(&br, &s.shapes))
        }
    }

    /// One triangle per leaf: every leaf reached is one test.
    fn work(tests_per_ray: f64) -> Work {
        Work { leaves: Some(tests_per_ray), tests: Some(tests_per_ray), nodes: None }
    }
}

/// The first hit among `candidates` within the ray's interval.
#[inline(always)]
fn first_hit<'a, const WT: bool, const COUNT: bool>(
    ray: &Ray,
    br: &BvhRay<f32, 3>,
    candidates: impl Iterator<Item = &'a BvhTriangle>,
) -> (Hit, u64) {
    let len = ray.dir().length();
    let sheared = WT.then(|| Watertight::prepare(ray));
    let mut tests = 0u64;
    for tri in candidates {
        tests += u64::from(COUNT);
        match &sheared {
            Some(sh) => {
                let [a, b, c] = tri.v.map(|p| Vec3::new(p.x, p.y, p.z));
                if let Some(h) = Watertight::intersect(sh, a, b, c, ray.tmin, ray.tmax) {
                    return (Hit { t: h.t, prim: tri.prim, u: h.u, v: h.v }, tests);
                }
            }
            None => {
                let x = br.intersects_triangle(&tri.v[0], &tri.v[1], &tri.v[2]);
                let t = x.distance / len;
                if t >= ray.tmin && t <= ray.tmax {
                    return (Hit { t, prim: tri.prim, u: x.u, v: x.v }, tests);
                }
            }
        }
    }
    (Hit::MISS, tests)
}

/// A raytrail ray as the crate takes it (normalized direction), and the direction's length.
#[inline(always)]
fn bvh_ray(r: &Ray) -> (BvhRay<f32, 3>, f32) {
    let d = r.dir();
    (BvhRay::new(Point3::new(r.origin[0], r.origin[1], r.origin[2]), Vector3::new(d.x, d.y, d.z)), d.length())
}
