//! obvhs 0.4: its binary BVH and its 8-wide compressed BVH (CWBVH, Ylitie et al. 2017), each built
//! with obvhs's own builder and traced with obvhs's own traversal.
//!
//! Both trees come from obvhs's `build_*_from_tris` helpers with `BvhBuildParams::medium_build()`,
//! the preset obvhs documents as "around the same build time as embree but with faster traversal"
//! and uses in its examples (PLOC, reinsertion; the BVH2 collapses to at most 8 triangles per leaf,
//! the CWBVH to at most 3). As obvhs's examples recommend, the triangles are stored in the tree's
//! primitive order, so a leaf's callback reads them without the `primitive_indices` indirection.
//!
//! obvhs's own hit rule: a closest hit replaces the current one only when strictly closer (ties go
//! to whichever triangle was tested first), and an any-hit query stops at a hit strictly before
//! `tmax`. Its triangle test is Möller-Trumbore without backface culling.

use super::PeerTree;
use crate::bench::report::Built;
use glam::{Vec3, Vec3A};
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray as ObvhsRay, RayHit, INVALID_ID};
use obvhs::triangle::Triangle as ObvhsTriangle;
use obvhs::BvhBuildParams;
use raytrail::core::intersect::{TriangleTest, Watertight};
use raytrail::core::scene::Scene;
use raytrail::core::{Hit, Ray};
use std::time::{Duration, Instant};

/// obvhs's closest-hit and occlusion traversals, the same for both of its trees.
pub trait ObvhsTree: Send + Sync + 'static {
    /// Closest hit: `test` returns the distance to a primitive (infinity for a miss).
    fn closest<F: FnMut(&ObvhsRay, usize) -> f32>(&self, ray: ObvhsRay, hit: &mut RayHit, test: F);
    /// Occlusion: stops at the first distance below `tmax` that `test` returns.
    fn occluded<F: FnMut(&ObvhsRay, usize) -> f32>(&self, ray: ObvhsRay, test: F);
}

impl ObvhsTree for Bvh2 {
    #[inline(always)]
    fn closest<F: FnMut(&ObvhsRay, usize) -> f32>(&self, ray: ObvhsRay, hit: &mut RayHit, test: F) {
        self.ray_traverse(ray, hit, test);
    }
    #[inline(always)]
    fn occluded<F: FnMut(&ObvhsRay, usize) -> f32>(&self, ray: ObvhsRay, test: F) {
        self.ray_traverse_miss(ray, test);
    }
}

impl ObvhsTree for CwBvh {
    #[inline(always)]
    fn closest<F: FnMut(&ObvhsRay, usize) -> f32>(&self, ray: ObvhsRay, hit: &mut RayHit, test: F) {
        self.ray_traverse(ray, hit, test);
    }
    #[inline(always)]
    fn occluded<F: FnMut(&ObvhsRay, usize) -> f32>(&self, ray: ObvhsRay, test: F) {
        self.ray_traverse_miss(ray, test);
    }
}

/// An obvhs tree with the scene's triangles in its primitive order.
pub struct ObvhsScene<T> {
    tree: T,
    /// Triangles by leaf slot.
    triangles: Vec<ObvhsTriangle>,
    /// raytrail primitive id by leaf slot.
    prims: Vec<u32>,
}

/// The scene's triangles as obvhs takes them.
fn obvhs_triangles(scene: &Scene) -> Vec<ObvhsTriangle> {
    scene
        .triangles()
        .iter()
        .map(|t| ObvhsTriangle { v0: t.v[0].into(), v1: t.v[1].into(), v2: t.v[2].into() })
        .collect()
}

impl<T> ObvhsScene<T> {
    /// Puts the triangles in the order of `primitive_indices`.
    fn new(tree: T, triangles: &[ObvhsTriangle], primitive_indices: &[u32]) -> Self {
        let prims = primitive_indices.to_vec();
        let triangles = prims.iter().map(|&p| triangles[p as usize]).collect();
        Self { tree, triangles, prims }
    }

    /// Builds a tree over `scene` with `build`, timing only that call; `layout` gives the tree's
    /// primitive order and node bytes. `what` names the build in the report.
    fn build_with(
        scene: &Scene,
        what: &str,
        build: impl FnOnce(&[ObvhsTriangle]) -> T,
        layout: impl Fn(&T) -> (&[u32], usize),
    ) -> (Self, Built) {
        let tris = obvhs_triangles(scene);
        let start = Instant::now();
        let tree = build(&tris);
        let seconds = start.elapsed().as_secs_f64();
        let (order, node_bytes) = layout(&tree);
        let order = order.to_vec();
        let s = Self::new(tree, &tris, &order);
        let mut bytes = vec![("nodes".to_string(), node_bytes)];
        bytes.extend(s.primitive_bytes());
        (s, Built { what: what.to_string(), seconds, bytes })
    }

    /// Bytes of the reordered triangles and the primitive map.
    fn primitive_bytes(&self) -> Vec<(String, usize)> {
        vec![
            ("primitive indices".to_string(), std::mem::size_of_val(self.prims.as_slice())),
            ("triangles (in leaf order)".to_string(), std::mem::size_of_val(self.triangles.as_slice())),
        ]
    }
}

impl ObvhsScene<Bvh2> {
    /// Builds obvhs's BVH2 over `scene` (on the current rayon pool).
    pub fn bvh2(scene: &Scene) -> (Self, Built) {
        Self::build_with(
            scene,
            "obvhs-bvh2 (PLOC, medium_build)",
            |tris| build_bvh2_from_tris(tris, BvhBuildParams::medium_build(), &mut Duration::default()),
            |t| (&t.primitive_indices, std::mem::size_of_val(t.nodes.as_slice())),
        )
    }
}

impl ObvhsScene<CwBvh> {
    /// Builds obvhs's CWBVH over `scene` (on the current rayon pool).
    pub fn cwbvh(scene: &Scene) -> (Self, Built) {
        Self::build_with(
            scene,
            "obvhs-cwbvh (PLOC, medium_build)",
            |tris| build_cwbvh_from_tris(tris, BvhBuildParams::medium_build(), &mut Duration::default()),
            |t| (&t.primitive_indices, std::mem::size_of_val(t.nodes.as_slice())),
        )
    }
}

impl<T: ObvhsTree> PeerTree for ObvhsScene<T> {
    /// Closest hit of one ray and the triangle tests made (counted when `COUNT`).
    #[inline(always)]
    fn closest<const WT: bool, const COUNT: bool>(&self, ray: &Ray) -> (Hit, u64) {
        let s = self;
        let sheared = WT.then(|| Watertight::prepare(ray));
        let (mut best, mut tests, mut found) = (Hit::MISS, 0u64, RayHit::none());
        s.tree.closest(obvhs_ray(ray), &mut found, |r, slot| {
            tests += u64::from(COUNT);
            let tri = &s.triangles[slot];
            match &sheared {
                Some(sh) => match Watertight::intersect(sh, v(tri.v0), v(tri.v1), v(tri.v2), r.tmin, r.tmax) {
                    Some(h) => {
                        let prim = s.prims[slot];
                        if best.is_beaten_by(h.t, prim) {
                            best = Hit { t: h.t, prim, u: h.u, v: h.v };
                        }
                        h.t
                    }
                    None => f32::INFINITY,
                },
                None => tri.intersect(r),
            }
        });
        if !WT && found.primitive_id != INVALID_ID {
            best = Hit { t: found.t, prim: s.prims[found.primitive_id as usize], u: 0.0, v: 0.0 };
        }
        (best, tests)
    }

    /// Any hit of one ray and the triangle tests made (counted when `COUNT`).
    #[inline(always)]
    fn any<const WT: bool, const COUNT: bool>(&self, ray: &Ray) -> (Hit, u64) {
        let s = self;
        let sheared = WT.then(|| Watertight::prepare(ray));
        let (mut found, mut tests) = (Hit::MISS, 0u64);
        s.tree.occluded(obvhs_ray(ray), |r, slot| {
            tests += u64::from(COUNT);
            let tri = &s.triangles[slot];
            match &sheared {
                Some(sh) => match Watertight::intersect(sh, v(tri.v0), v(tri.v1), v(tri.v2), r.tmin, r.tmax) {
                    Some(h) => {
                        found = Hit { t: h.t, prim: s.prims[slot], u: h.u, v: h.v };
                        // raytrail's interval is inclusive: stop even at t = tmax.
                        f32::NEG_INFINITY
                    }
                    None => f32::INFINITY,
                },
                None => {
                    let t = tri.intersect(r);
                    if t < r.tmax {
                        found = Hit { t, prim: s.prims[slot], u: 0.0, v: 0.0 };
                    }
                    t
                }
            }
        });
        (found, tests)
    }
}

/// A raytrail ray as obvhs takes it (obvhs precomputes a clamped reciprocal direction).
#[inline(always)]
fn obvhs_ray(r: &Ray) -> ObvhsRay {
    ObvhsRay::new(Vec3A::from(r.origin()), Vec3A::from(r.dir()), r.tmin, r.tmax)
}

/// An obvhs vertex as raytrail's tests take it.
#[inline(always)]
fn v(p: Vec3A) -> Vec3 {
    Vec3::from(p)
}
