use super::{TriangleHit, TriangleTest};
use crate::Ray;
use glam::Vec3;

/// The watertight ray/triangle test of Woop, Benthin and Wald (2013), the default.
///
/// The ray is sheared so it runs along +z; edge functions are evaluated in 2D and recomputed in
/// `f64` when one is exactly zero, so that a ray through a shared edge or vertex hits exactly one
/// of the triangles sharing it (no cracks, no double hits). Backfaces are not culled.
#[derive(Clone, Copy, Debug, Default)]
pub struct Watertight;

/// Per-ray constants of the watertight test.
#[derive(Clone, Copy, Debug)]
pub struct ShearedRay {
    origin: Vec3,
    /// Axis permutation: `kx`, `ky`, `kz`, with `kz` the dominant direction axis.
    k: [usize; 3],
    /// Shear constants `dx/dz`, `dy/dz`, `1/dz`.
    s: [f32; 3],
}

impl TriangleTest for Watertight {
    type PerRay = ShearedRay;
    const NAME: &'static str = "watertight";

    #[inline]
    fn prepare(ray: &Ray) -> ShearedRay {
        let d = ray.dir();
        let a = d.abs();
        // Dominant axis; ties go to the lower axis so every backend picks the same one.
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Swapping keeps the winding, so the sign of the determinant keeps its meaning.
        if d[kz] < 0.0 {
            core::mem::swap(&mut kx, &mut ky);
        }
        let dz = d[kz];
        ShearedRay { origin: ray.origin(), k: [kx, ky, kz], s: [d[kx] / dz, d[ky] / dz, 1.0 / dz] }
    }

    #[inline(always)]
    fn intersect(r: &ShearedRay, a: Vec3, b: Vec3, c: Vec3, tmin: f32, tmax: f32) -> Option<TriangleHit> {
        let [kx, ky, kz] = r.k;
        let [sx, sy, sz] = r.s;
        let a = a - r.origin;
        let b = b - r.origin;
        let c = c - r.origin;
        let ax = a[kx] - sx * a[kz];
        let ay = a[ky] - sy * a[kz];
        let bx = b[kx] - sx * b[kz];
        let by = b[ky] - sy * b[kz];
        let cx = c[kx] - sx * c[kz];
        let cy = c[ky] - sy * c[kz];
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let f = |p: f32, q: f32, r: f32, s: f32| (p as f64 * q as f64 - r as f64 * s as f64) as f32;
            u = f(cx, by, cy, bx);
            v = f(ax, cy, ay, cx);
            w = f(bx, ay, by, ax);
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let az = sz * a[kz];
        let bz = sz * b[kz];
        let cz = sz * c[kz];
        let t = (u * az + v * bz + w * cz) / det;
        // A `t` that overflowed (directions near the float limits) is no hit.
        if !t.is_finite() || t < tmin || t > tmax {
            return None;
        }
        Some(TriangleHit { t, u: v / det, v: w / det })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shoot(o: Vec3, d: Vec3, tri: [Vec3; 3]) -> Option<TriangleHit> {
        let r = Watertight::prepare(&Ray::new(o, d, 0.0, f32::INFINITY));
        Watertight::intersect(&r, tri[0], tri[1], tri[2], 0.0, f32::INFINITY)
    }

    #[test]
    fn hits_center_with_barycentrics() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let h = shoot(Vec3::new(0.25, 0.25, 1.0), Vec3::NEG_Z, tri).unwrap();
        assert_eq!(h.t, 1.0);
        assert!((h.u - 0.25).abs() < 1e-6 && (h.v - 0.25).abs() < 1e-6);
        // Backface: same triangle from below.
        assert_eq!(shoot(Vec3::new(0.25, 0.25, -1.0), Vec3::Z, tri).unwrap().t, 1.0);
    }

    #[test]
    fn no_crack_along_a_shared_edge() {
        // Two triangles share the diagonal of the unit square; oblique rays aimed at the diagonal.
        let t0 = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)];
        let t1 = [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        for i in 1..1000 {
            let s = i as f32 / 1000.0;
            let d = Vec3::new(0.013 * s, -0.007, -1.0);
            let o = Vec3::new(s, s, 0.0) - 3.0 * d;
            let hits = shoot(o, d, t0).is_some() as u32 + shoot(o, d, t1).is_some() as u32;
            assert!(hits >= 1, "crack at s = {s}");
        }
    }

    #[test]
    fn misses_outside_and_respects_interval() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(shoot(Vec3::new(0.75, 0.75, 1.0), Vec3::NEG_Z, tri).is_none());
        let r = Watertight::prepare(&Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z, 0.0, 0.5));
        assert!(Watertight::intersect(&r, tri[0], tri[1], tri[2], 0.0, 0.5).is_none());
    }
}
