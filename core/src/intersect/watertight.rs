use super::{TriangleHit, TriangleTest};
use crate::Ray;
use glam::{Vec3, Vec3A};

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
    /// The origin's coordinates in the permuted order `o[kx], o[ky], o[kz]`.
    origin: [f32; 3],
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
        let o = ray.origin;
        // `dx/dz, dy/dz, 1/dz` as one 4-wide division where SIMD is available (IEEE per lane).
        let s = Vec3A::new(d[kx], d[ky], 1.0) / Vec3A::splat(dz);
        ShearedRay { origin: [o[kx], o[ky], o[kz]], k: [kx, ky, kz], s: s.to_array() }
    }

    #[inline(always)]
    fn intersect(r: &ShearedRay, a: Vec3, b: Vec3, c: Vec3, tmin: f32, tmax: f32) -> Option<TriangleHit> {
        Self::intersect_in_place(r, [a.as_ref(), b.as_ref(), c.as_ref()], tmin, tmax)
    }

    /// The test proper. Coordinates are picked by the ray's permutation straight from where the
    /// vertices are stored: an index into values held in registers costs a chain of branches or a
    /// trip through memory per coordinate.
    #[inline(always)]
    fn intersect_in_place(r: &ShearedRay, v: [&[f32; 3]; 3], tmin: f32, tmax: f32) -> Option<TriangleHit> {
        let [kx, ky, kz] = r.k;
        let [ox, oy, oz] = r.origin;
        let [sx, sy, sz] = r.s;
        // Each vertex relative to the origin, in ray-space axis order (the same subtractions as
        // `v - origin` followed by the permutation).
        let [a, b, c] = v.map(|p| [p[kx] - ox, p[ky] - oy, p[kz] - oz]);
        let ax = a[0] - sx * a[2];
        let ay = a[1] - sy * a[2];
        let bx = b[0] - sx * b[2];
        let by = b[1] - sy * b[2];
        let cx = c[0] - sx * c[2];
        let cy = c[1] - sy * c[2];
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
        let az = sz * a[2];
        let bz = sz * b[2];
        let cz = sz * c[2];
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

    /// The test as first written (on `Vec3`s, `v - origin` then the permutation): the reference
    /// that the in-place reads must match bit for bit.
    fn reference(ray: &Ray, a: Vec3, b: Vec3, c: Vec3) -> Option<TriangleHit> {
        let d = ray.dir();
        let m = d.abs();
        let kz = if m.x >= m.y && m.x >= m.z {
            0
        } else if m.y >= m.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if d[kz] < 0.0 {
            core::mem::swap(&mut kx, &mut ky);
        }
        let (sx, sy, sz) = (d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
        let (a, b, c) = (a - ray.origin(), b - ray.origin(), c - ray.origin());
        let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
        let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
        let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
        let (mut u, mut v, mut w) = (cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax);
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let f = |p: f32, q: f32, r: f32, s: f32| (p as f64 * q as f64 - r as f64 * s as f64) as f32;
            (u, v, w) = (f(cx, by, cy, bx), f(ax, cy, ay, cx), f(bx, ay, by, ax));
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t = (u * (sz * a[kz]) + v * (sz * b[kz]) + w * (sz * c[kz])) / det;
        if !t.is_finite() || t < ray.tmin || t > ray.tmax {
            return None;
        }
        Some(TriangleHit { t, u: v / det, v: w / det })
    }

    #[test]
    fn matches_the_reference_bit_for_bit() {
        // Small integer grids make exact zeros (edges and vertices hit dead on) common.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % 9) as f32 - 4.0 + if state & 1 << 40 != 0 { 0.0 } else { 0.37 }
        };
        let (mut hits, mut per_k) = (0, [0; 3]);
        for _ in 0..100_000 {
            let mut v = || Vec3::new(next(), next(), next());
            let (o, d, a, b, c) = (v(), v(), v(), v(), v());
            if d == Vec3::ZERO {
                continue;
            }
            let ray = Ray::new(o, d, 0.0, f32::INFINITY);
            let r = Watertight::prepare(&ray);
            per_k[r.k[2]] += 1;
            let fast = Watertight::intersect(&r, a, b, c, ray.tmin, ray.tmax);
            let slow = reference(&ray, a, b, c);
            let bits = |h: Option<TriangleHit>| h.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits()));
            assert_eq!(bits(fast), bits(slow), "ray {ray:?}, triangle {a} {b} {c}");
            hits += fast.is_some() as u32;
        }
        assert!(hits > 1000 && per_k.iter().all(|&n| n > 1000), "{hits} hits, permutations {per_k:?}");
    }
}
