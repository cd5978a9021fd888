//! Scenes of one to a dozen triangles: trees that are a single leaf or barely more, flat and
//! zero-volume bounds, coincident triangles.

use super::{scene_of, NamedScene};
use glam::Vec3;
use raytrail_core::geometry::Triangle;

/// The corner-case scenes:
/// - `single_triangle`: one triangle in `z = 0` (the tree is one leaf; its box is flat).
/// - `two_triangles`: a unit square split along its diagonal (one shared edge).
/// - `tetrahedron`: a closed regular tetrahedron, outward winding.
/// - `coplanar_stack`: axis-aligned right triangles in the planes `z = 0, 1, 2`; in each, two
///   identical copies, one with reversed winding and a smaller overlapping one, so hits tie at
///   equal `t` and the smaller primitive id must win.
/// - `zero_area`: only degenerate triangles (collinear, and a point); the scene's box is a segment.
pub fn tiny_cases() -> Vec<NamedScene> {
    let v = Vec3::new;
    let tri = |a, b, c| Triangle::new(a, b, c);
    let single = vec![tri(v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0))];
    let (a, b, c, d) = (v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(1.0, 1.0, 0.0), v(0.0, 1.0, 0.0));
    let two = vec![tri(a, b, c), tri(a, c, d)];
    let (p, q, r, s) = (v(1.0, 1.0, 1.0), v(1.0, -1.0, -1.0), v(-1.0, 1.0, -1.0), v(-1.0, -1.0, 1.0));
    let tetra = vec![tri(p, q, r), tri(p, s, q), tri(p, r, s), tri(q, s, r)];
    let mut stack = Vec::new();
    for z in [0.0, 1.0, 2.0] {
        let (o, x2, y2) = (v(0.0, 0.0, z), v(2.0, 0.0, z), v(0.0, 2.0, z));
        stack.extend([tri(o, x2, y2), tri(o, x2, y2), tri(o, y2, x2), tri(o, v(1.0, 0.0, z), v(0.0, 1.0, z))]);
    }
    let zero_area = vec![
        tri(v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0), v(2.0, 2.0, 2.0)),
        tri(v(0.5, 0.5, 0.5), v(0.5, 0.5, 0.5), v(0.5, 0.5, 0.5)),
    ];
    [
        ("single_triangle", single),
        ("two_triangles", two),
        ("tetrahedron", tetra),
        ("coplanar_stack", stack),
        ("zero_area", zero_area),
    ]
    .into_iter()
    .map(|(name, tris)| NamedScene::new(name, scene_of(tris)))
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tetrahedron_winds_outward() {
        let cases = tiny_cases();
        let tetra = &cases.iter().find(|c| c.name == "tetrahedron").unwrap().scene;
        for t in tetra.triangles() {
            let n = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
            assert!(n.dot(t.centroid()) > 0.0);
        }
    }
}
