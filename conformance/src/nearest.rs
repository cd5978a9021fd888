//! The nearest point by brute force: every triangle tested with the same per-triangle rule as
//! the tree walk ([`closest_point_on_triangle`]), ties to the lower primitive id, so the walk's
//! answer must equal it bit for bit.

use raytrail_core::nearest::{closest_point_on_triangle, NearestPoint};
use raytrail_core::scene::Scene;

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
