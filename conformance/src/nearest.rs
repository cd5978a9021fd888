//! The nearest point by brute force: every triangle tested with the same per-triangle rule as
//! the tree walk ([`closest_point_on_triangle`]), ties to the lower primitive id, so the walk's
//! answer must equal it bit for bit. [`check_backend`] is the conformance suite's nearest-point
//! case ([`crate::suite::Case::Nearest`]).

use crate::rays::query_points;
use crate::scenes::{far_from_origin, shared_edge_grid, sphereflake, triangle_soup};
use raytrail_core::bvh2::{Bvh2, SahBuilder, SbvhBuilder};
use raytrail_core::nearest::{closest_point_on_triangle, NearestPoint};
use raytrail_core::scene::Scene;
use raytrail_core::trace::Trace;

/// The point of `scene` nearest to `p` within `radius` (inclusive), over every triangle.
pub fn brute_force(scene: &Scene, p: [f32; 3], radius: f32) -> Option<NearestPoint> {
    let q = glam::Vec3::from_array(p);
    let mut best: Option<(f32, NearestPoint)> = None;
    for (prim, t) in scene.triangles().iter().enumerate() {
        let on = closest_point_on_triangle(q, t.v[0], t.v[1], t.v[2]);
        if on.distance2 <= radius * radius && best.is_none_or(|(d, _)| on.distance2 < d) {
            let found = NearestPoint {
                prim: prim as u32,
                u: on.u,
                v: on.v,
                point: on.point.to_array(),
                distance: on.distance2.sqrt(),
            };
            best = Some((on.distance2, found));
        }
    }
    best.map(|(_, n)| n)
}

/// The suite's nearest-point case on `backend`: points in and around the shared-edge grid, the
/// sphereflake (with a SAH and a split tree), a triangle soup and the scene far from the origin,
/// each prepared as [`crate::all_hits::prepared_for_queries`] prepares it, with no radius, a radius of a twentieth
/// of the scene and a radius of 0; every answer must be the brute force's bit for bit. Panics with
/// a loud report otherwise, or when the backend has no nearest-point query.
pub fn check_backend<B: Trace>(backend: &B) {
    let sah = |s: &Scene| SahBuilder::default().build(s.triangles()).expect("SAH build");
    let flake = sphereflake(2);
    let split = SbvhBuilder::default().build(flake.triangles()).expect("SBVH build");
    assert!(split.has_split_references(), "the sphereflake's SBVH tree should cut triangles");
    check_scene(backend, "shared_edge_grid", &shared_edge_grid(8), sah);
    check_scene(backend, "sphereflake", &flake, sah);
    check_scene(backend, "sphereflake (SBVH)", &flake, |_| split);
    check_scene(backend, "triangle_soup", &triangle_soup(1500, 11), sah);
    check_scene(backend, "far_from_origin", &far_from_origin(), sah);
}

/// [`check_backend`] on one scene with the tree `build` makes.
fn check_scene<B: Trace>(backend: &B, name: &str, scene: &Scene, build: impl FnOnce(&Scene) -> Bvh2) {
    let prepared = crate::all_hits::prepared_for_queries(scene, build(scene));
    let device = backend.prepare(prepared).expect("prepare on the backend");
    let points = query_points(scene, 300, 0.5, 17);
    let size = (scene.bounds().max - scene.bounds().min).max_element();
    for radius in [f32::INFINITY, size * 0.05, 0.0] {
        let what = format!("backend {}, scene {name}, radius {radius}", backend.name());
        let got = backend
            .nearest_points(&device, &points, radius)
            .unwrap_or_else(|e| panic!("NOT CONFORMING: {what}: nearest points failed: {e}"));
        assert_eq!(got.len(), points.len(), "NOT CONFORMING: {what}: answers for {} points", points.len());
        let wrong: Vec<String> = points
            .iter()
            .zip(&got)
            .filter_map(|(p, g)| {
                let want = brute_force(scene, *p, radius);
                (*g != want).then(|| format!("point {p:?}: expected {want:?}, got {g:?}"))
            })
            .collect();
        assert!(
            wrong.is_empty(),
            "NOT CONFORMING: {what}: {} of {} points differ from the brute force: {:?}",
            wrong.len(),
            points.len(),
            &wrong[..wrong.len().min(3)]
        );
        let found = got.iter().filter(|g| g.is_some()).count();
        assert!(radius != f32::INFINITY || found == points.len(), "{what}: {found} points found a nearest point");
    }
}
