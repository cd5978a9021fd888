use super::{TriangleHit, TriangleTest};
use crate::Ray;
use glam::Vec3;

/// The Möller-Trumbore test (1997): fast but not watertight; rays through shared edges can slip
/// between triangles. Kept for run-time-against-error comparisons.
#[derive(Clone, Copy, Debug, Default)]
pub struct MollerTrumbore;

/// Per-ray constants of the Möller-Trumbore test.
#[derive(Clone, Copy, Debug)]
pub struct PlainRay {
    origin: Vec3,
    dir: Vec3,
}

impl TriangleTest for MollerTrumbore {
    type PerRay = PlainRay;
    const NAME: &'static str = "moller-trumbore";

    #[inline]
    fn prepare(ray: &Ray) -> PlainRay {
        PlainRay { origin: ray.origin(), dir: ray.dir() }
    }

    #[inline(always)]
    fn intersect(r: &PlainRay, a: Vec3, b: Vec3, c: Vec3, tmin: f32, tmax: f32) -> Option<TriangleHit> {
        let e1 = b - a;
        let e2 = c - a;
        let p = r.dir.cross(e2);
        let det = e1.dot(p);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv = 1.0 / det;
        let s = r.origin - a;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(e1);
        let v = r.dir.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = e2.dot(q) * inv;
        // A `t` that overflowed (directions near the float limits) is no hit.
        if !t.is_finite() || t < tmin || t > tmax {
            return None;
        }
        Some(TriangleHit { t, u, v })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agrees_with_watertight_inside() {
        use crate::intersect::Watertight;
        let tri = [Vec3::new(-1.0, -1.0, 2.0), Vec3::new(2.0, -0.5, 3.0), Vec3::new(0.0, 2.0, 2.5)];
        let ray = Ray::new(Vec3::ZERO, Vec3::new(0.1, 0.2, 1.0), 0.0, f32::INFINITY);
        let m = MollerTrumbore::intersect(&MollerTrumbore::prepare(&ray), tri[0], tri[1], tri[2], 0.0, 1e30).unwrap();
        let w = Watertight::intersect(&Watertight::prepare(&ray), tri[0], tri[1], tri[2], 0.0, 1e30).unwrap();
        assert!((m.t - w.t).abs() < 1e-5 && (m.u - w.u).abs() < 1e-5 && (m.v - w.v).abs() < 1e-5);
    }
}
