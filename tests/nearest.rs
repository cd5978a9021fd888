//! The nearest point on the mesh ([`Tracer::nearest_points`]): bit for bit a brute force over
//! every triangle with the same per-triangle rule, within a radius or without one, on scenes of
//! ordinary size and on one prepared at another scale; errors for bad radii.

use raytrail::{Error, TracerBuilder};
use raytrail_conformance::nearest::brute_force;
use raytrail_conformance::rays::query_points;
use raytrail_conformance::scenes::{far_from_origin, shared_edge_grid, sphereflake, triangle_soup};

#[test]
fn nearest_points_are_a_brute_force_s_bit_for_bit() {
    let scenes = [shared_edge_grid(8), sphereflake(2), triangle_soup(1500, 11), far_from_origin()];
    for (k, scene) in scenes.iter().enumerate() {
        let tracer = TracerBuilder::default().build_scene(scene).unwrap();
        let pts = query_points(scene, 300, 0.5, 17);
        let size = (scene.bounds().max - scene.bounds().min).max_element();
        for radius in [f32::INFINITY, size * 0.05, 0.0] {
            let got = tracer.nearest_points(&pts, radius).unwrap();
            let mut found = 0;
            for (p, g) in pts.iter().zip(&got) {
                let want = brute_force(scene, *p, radius);
                assert_eq!(*g, want, "scene {k}, point {p:?}, radius {radius}");
                found += g.is_some() as usize;
            }
            if radius == f32::INFINITY {
                assert_eq!(found, pts.len(), "scene {k}: every point has a nearest point");
            }
        }
    }
}

#[test]
fn a_point_on_the_surface_is_at_distance_zero_and_bad_input_is_no_panic() {
    let scene = shared_edge_grid(8);
    let tracer = TracerBuilder::default().build_scene(&scene).unwrap();
    let on = tracer.nearest_points(&[[0.3, 0.1, 0.0]], 0.0).unwrap();
    assert_eq!(on[0].map(|n| (n.point, n.distance)), Some(([0.3, 0.1, 0.0], 0.0)));
    let odd = tracer.nearest_points(&[[f32::NAN, 0.0, 0.0], [f32::INFINITY, 0.0, 0.0]], f32::INFINITY).unwrap();
    assert_eq!(odd, vec![None, None]);
    for radius in [-1.0, f32::NAN] {
        let err = tracer.nearest_points(&[[0.0; 3]], radius).unwrap_err();
        assert!(matches!(err, Error::InvalidRadius(_)), "{err}");
    }
}
