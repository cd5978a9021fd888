//! Random, overlapping triangles of all sizes and shapes, degenerate ones included.

use super::scene_of;
use crate::rng::Pcg32;
use glam::Vec3;
use raytrail_core::geometry::Triangle;
use raytrail_core::scene::Scene;

/// Half the side of the soup's box, centered at the origin.
const HALF: f32 = 4.0;

/// `n` random triangles in the box `[-4, 4]^3` (vertices clamped to it), sizes spread over eight
/// octaves from 0.01 to 2.56. Mix, by probability:
/// - 72% ordinary triangles,
/// - 12% slivers (long and nearly collinear),
/// - 6% needles (two vertices a millionth of the size apart),
/// - 4% exactly collinear (zero area; the vertices differ along one axis only),
/// - 2% with two equal vertices, 2% with all three equal (a point),
/// - 2% exact copies of an earlier triangle, half of them with reversed winding (equal `t` ties).
///
/// Panics if `n` is 0.
pub fn triangle_soup(n: usize, seed: u64) -> Scene {
    assert!(n > 0, "triangle_soup: n must be positive");
    let mut rng = Pcg32::new(seed, 0x50_u64);
    let (lo, hi) = (Vec3::splat(-HALF), Vec3::splat(HALF));
    let mut tris: Vec<Triangle> = Vec::with_capacity(n);
    while tris.len() < n {
        let a = rng.in_box(lo, hi);
        // Roughly log-uniform without `powf`: a random octave, uniform within it.
        let size = 0.01 * (1u32 << rng.below(8)) as f32 * (1.0 + rng.next_f32());
        let dir = rng.unit_vector();
        let kind = rng.next_f32();
        let t = if kind < 0.72 {
            let b = a + rng.unit_vector() * size * rng.range_f32(0.3, 1.0);
            let c = a + rng.unit_vector() * size * rng.range_f32(0.3, 1.0);
            Triangle::new(a, b, c)
        } else if kind < 0.84 {
            let b = a + dir * size;
            let (side, _) = dir.any_orthonormal_pair();
            Triangle::new(a, b, (a + b) * 0.5 + side * size * 1e-4)
        } else if kind < 0.90 {
            Triangle::new(a, a + rng.unit_vector() * size * 1e-6, a + dir * size)
        } else if kind < 0.94 {
            // Only one coordinate varies, so the three points are collinear exactly, whatever the
            // rounding of that coordinate.
            let axis = rng.index(3);
            let (mut b, mut c) = (a, a);
            b[axis] += size;
            c[axis] += size * rng.next_f32();
            Triangle::new(a, b, c)
        } else if kind < 0.96 {
            Triangle::new(a, a, a + dir * size)
        } else if kind < 0.98 {
            Triangle::new(a, a, a)
        } else if let Some(&earlier) = tris.get(rng.index(tris.len().max(1))) {
            if rng.next_u32() & 1 == 0 {
                earlier
            } else {
                Triangle::new(earlier.v[0], earlier.v[2], earlier.v[1])
            }
        } else {
            continue;
        };
        tris.push(Triangle { v: t.v.map(|p| p.clamp(lo, hi)) });
    }
    scene_of(tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deterministic_with_degenerates() {
        let a = triangle_soup(2_000, 9);
        assert_eq!(a, triangle_soup(2_000, 9));
        assert_ne!(a, triangle_soup(2_000, 10));
        let area = |t: &Triangle| (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]).length();
        let zero = a.triangles().iter().filter(|t| area(t) == 0.0).count();
        assert!(zero > 50, "only {zero} zero-area triangles");
        let b = a.bounds();
        assert!(b.min.cmpge(Vec3::splat(-HALF)).all() && b.max.cmple(Vec3::splat(HALF)).all());
    }
}
