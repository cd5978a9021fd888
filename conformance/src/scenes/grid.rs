//! Grids of quads whose triangles share edges and vertices exactly: rays through those edges and
//! vertices must hit exactly one triangle (no cracks, no double hits) with a watertight test.

use super::scene_of;
use glam::{Quat, Vec3};
use raytrail_core::geometry::Triangle;
use raytrail_core::scene::Scene;

/// Two `n` x `n` grids of quads, each quad split into two triangles (`4 n^2` triangles).
///
/// The first grid lies in the plane `z = 0` over `[-1, 1]^2`; with `n` a power of two its vertex
/// coordinates are exact binary fractions, so axis-aligned rays can pass exactly through its edges
/// and vertices. The second is the same grid rotated about a skew axis and lifted to around
/// `z = 3`, so its shared edges run in no special direction. Every vertex is computed once and
/// copied into each triangle that uses it, so shared vertices are bit-identical. The diagonal
/// alternates in a checkerboard, giving vertices shared by four and by eight triangles.
/// Panics if `n` is 0.
pub fn shared_edge_grid(n: usize) -> Scene {
    assert!(n > 0, "shared_edge_grid: n must be positive");
    // About 40 degrees about a skew axis, from quaternion components (no platform `sin`/`cos`).
    let rotation = Quat::from_xyzw(0.1, 0.2, 0.3, 0.9).normalize();
    let lift = Vec3::new(0.25, -0.125, 3.0);
    let mut tris = Vec::with_capacity(4 * n * n);
    push_placed_grid(n, |p| p, &mut tris);
    push_placed_grid(n, |p| rotation * p + lift, &mut tris);
    scene_of(tris)
}

/// Pushes one `n` x `n` flat grid over `[-1, 1]^2` (`2 n^2` triangles), each vertex mapped once
/// through `place`, so the copies of a shared vertex stay bit-identical.
pub(super) fn push_placed_grid(n: usize, place: impl Fn(Vec3) -> Vec3, out: &mut Vec<Triangle>) {
    let verts: Vec<Vec3> = grid_vertices(n).into_iter().map(place).collect();
    push_grid_triangles(n, &verts, out);
}

/// The `(n + 1)^2` vertices of the flat grid, row by row (`index = j * (n + 1) + i`).
fn grid_vertices(n: usize) -> Vec<Vec3> {
    let step = 2.0 / n as f32;
    let mut v = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            v.push(Vec3::new(i as f32 * step - 1.0, j as f32 * step - 1.0, 0.0));
        }
    }
    v
}

/// Two triangles per quad, counter-clockwise seen from the grid's +z side.
fn push_grid_triangles(n: usize, v: &[Vec3], out: &mut Vec<Triangle>) {
    let at = |i: usize, j: usize| v[j * (n + 1) + i];
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if (i + j) % 2 == 0 {
                out.push(Triangle::new(a, b, c));
                out.push(Triangle::new(a, c, d));
            } else {
                out.push(Triangle::new(a, b, d));
                out.push(Triangle::new(b, c, d));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    #[test]
    fn every_interior_edge_is_shared_by_exactly_two_triangles() {
        let n = 8;
        let scene = shared_edge_grid(n);
        assert_eq!(scene.triangles().len(), 4 * n * n);
        let key = |p: Vec3| p.to_array().map(f32::to_bits);
        let mut edges: HashMap<_, usize> = HashMap::new();
        for t in scene.triangles() {
            for k in 0..3 {
                let (a, b) = (key(t.v[k]), key(t.v[(k + 1) % 3]));
                *edges.entry(if a < b { (a, b) } else { (b, a) }).or_default() += 1;
            }
        }
        // Per grid: 2n(n+1) grid edges (4n on the border) and n^2 diagonals.
        let boundary = edges.values().filter(|&&c| c == 1).count();
        let shared = edges.values().filter(|&&c| c == 2).count();
        assert_eq!(boundary, 2 * 4 * n);
        assert_eq!(shared, 2 * (2 * n * (n + 1) - 4 * n + n * n));
        assert_eq!(boundary + shared, edges.len());
    }
}
