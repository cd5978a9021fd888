//! The nearest point on the mesh through [`Tracer::nearest_points`]: a point on the surface, odd
//! points and bad radii. That the answers are a brute force's bit for bit on every backend is the
//! conformance suite's nearest-point case (`raytrail_conformance::nearest::check_backend`).

use raytrail::{Error, TracerBuilder};
use raytrail_conformance::scenes::shared_edge_grid;

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
