//! The `f64` filter in front of the exact test: the same determinants as [`super::triangle`],
//! computed in `f64` with a bound on their error, so that a triangle is decided here only where
//! every sign (and the interval test) is certain, and otherwise goes to the exact test.
//!
//! The bound: every input is an `f32`, exact in `f64`. A difference of two is within `eps` of its
//! value relatively (`eps = 2^-53`); a 3x3 determinant of such differences is a sum of six triple
//! products, each within `5 eps` relatively, summed with two more roundings each. So
//! `|computed - exact| <= 8 eps * sum |x_i y_j z_k|`; the filter uses `32 eps` of that sum.
//! Nothing underflows or overflows: triple products of `f32` magnitudes lie within `2^-447 ..
//! 2^384`, far inside `f64`'s range.

use raytrail_core::geometry::Triangle;
use raytrail_core::Ray;

const EPS: f64 = 1.0 / 9_007_199_254_740_992.0; // 2^-53
const BOUND: f64 = 32.0 * EPS;

/// What the filter concludes about one triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filtered {
    /// Certainly no hit.
    Miss,
    /// Certainly a hit, at a `t` within `[lo, hi]`.
    Hit {
        /// Lower bound on `t`.
        lo: f64,
        /// Upper bound on `t`.
        hi: f64,
    },
    /// The bound is inconclusive: the exact test decides; `t` (if it is a hit) is within
    /// `[lo, hi]` (infinite where the plane test itself is in doubt).
    Unsure {
        /// Lower bound on `t`, where known.
        lo: f64,
        /// Upper bound on `t`, where known.
        hi: f64,
    },
}

/// A value and a bound on its error.
#[derive(Clone, Copy, Debug)]
struct Bounded {
    v: f64,
    err: f64,
}

impl Bounded {
    fn sign(self) -> Option<i8> {
        if self.v.abs() > self.err {
            Some(if self.v > 0.0 { 1 } else { -1 })
        } else {
            None
        }
    }
}

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn det(x: V, y: V, z: V) -> Bounded {
    let v =
        x[0] * (y[1] * z[2] - y[2] * z[1]) + x[1] * (y[2] * z[0] - y[0] * z[2]) + x[2] * (y[0] * z[1] - y[1] * z[0]);
    let a = |p: V| p.map(f64::abs);
    let (x, y, z) = (a(x), a(y), a(z));
    let perm =
        x[0] * (y[1] * z[2] + y[2] * z[1]) + x[1] * (y[2] * z[0] + y[0] * z[2]) + x[2] * (y[0] * z[1] + y[1] * z[0]);
    Bounded { v, err: BOUND * perm }
}

fn v64(p: [f32; 3]) -> V {
    p.map(f64::from)
}

/// The filter's verdict on `ray` against `tri` (for a traceable ray: finite inputs).
pub fn filter(ray: &Ray, tri: &Triangle) -> Filtered {
    let (o, d) = (v64(ray.origin), v64(ray.dir));
    let [a, b, c] = tri.v.map(|p| v64(p.to_array()));
    let (e1, e2, s) = (sub(b, a), sub(c, a), sub(o, a));
    let nd = d.map(|x| -x);
    let m = det(e1, e2, nd);
    let beta = det(s, e2, nd);
    let gamma = det(e1, s, nd);
    let alpha = Bounded {
        v: m.v - beta.v - gamma.v,
        err: m.err + beta.err + gamma.err + 4.0 * EPS * (m.v.abs() + beta.v.abs() + gamma.v.abs()),
    };
    let num = det(e1, e2, s);
    let Some(ms) = m.sign() else {
        return Filtered::Unsure { lo: f64::NEG_INFINITY, hi: f64::INFINITY };
    };
    let signs = [alpha.sign(), beta.sign(), gamma.sign()];
    if signs.iter().any(|s| *s == Some(-ms)) {
        return Filtered::Miss;
    }
    // t = num / m within its bound (m's sign is certain, so |m| > err).
    let (n, md) = if ms > 0 { (num.v, m.v) } else { (-num.v, -m.v) };
    let (nlo, nhi) = (n - num.err, n + num.err);
    let (dlo, dhi) = (md - m.err, md + m.err);
    let q = |x: f64, y: f64| x / y;
    let lo = if nlo >= 0.0 { q(nlo, dhi) } else { q(nlo, dlo) };
    let hi = if nhi >= 0.0 { q(nhi, dlo) } else { q(nhi, dhi) };
    let (lo, hi) = (lo - 4.0 * EPS * lo.abs(), hi + 4.0 * EPS * hi.abs());
    let (tmin, tmax) = (f64::from(ray.tmin), f64::from(ray.tmax));
    if hi < tmin || lo > tmax {
        return Filtered::Miss;
    }
    if signs.iter().all(|s| *s == Some(ms)) && lo >= tmin && hi <= tmax {
        Filtered::Hit { lo, hi }
    } else {
        Filtered::Unsure { lo, hi }
    }
}

/// The signed distance (in scene units, `f64`) across `ray` from its line to `tri`'s boundary:
/// measured in the plane perpendicular to the ray's direction, positive where the line passes
/// inside, negative outside. A triangle seen edge-on (the ray parallel to its plane, or the
/// triangle degenerate) projects to a segment or a point that no line passes inside: its margin
/// is minus the line's distance from that segment, so 0 for a ray in the triangle's plane that
/// crosses it (a rounded copy of that ray, a mapped instance ray for one, may hit it). `None`
/// only for a zero or non-finite direction.
/// Across the ray, not in the triangle's plane, because that is where a watertight test errs:
/// it decides the edges in the ray's own sheared 2D frame (Woop, Benthin & Wald 2013), so its
/// rounding moves an edge across the ray; a graze stretches that in the plane by `1 / sin`.
/// For tolerances, not for decisions.
pub fn margin(ray: &Ray, tri: &Triangle) -> Option<f64> {
    let (o, d) = (v64(ray.origin), v64(ray.dir));
    let len = |p: V| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    let dn = len(d);
    if dn == 0.0 || !dn.is_finite() {
        return None;
    }
    let u = d.map(|x| x / dn);
    let [a, b, c] = tri.v.map(|p| sub(v64(p.to_array()), o));
    // Each edge's signed double area with the line in the projected plane, and the length of
    // the projected edge: their ratio is the line's distance from that edge.
    let edge = |p: V, q: V| (dot(cross(p, q), u), len(cross(sub(q, p), u)));
    let edges = [edge(b, c), edge(c, a), edge(a, b)];
    let area = edges.iter().map(|e| e.0).sum::<f64>();
    if !area.is_finite() {
        return None;
    }
    if area == 0.0 || edges.iter().any(|e| e.1 == 0.0) {
        let flat = |p: V| sub(p, u.map(|x| x * dot(p, u)));
        let [a, b, c] = [a, b, c].map(flat);
        let gap =
            [(a, b), (b, c), (c, a)].map(|(p, q)| segment_distance(p, q)).into_iter().fold(f64::INFINITY, f64::min);
        return gap.is_finite().then_some(-gap);
    }
    let m = edges.iter().map(|&(s, l)| area.signum() * s / l).fold(f64::INFINITY, f64::min);
    m.is_finite().then_some(m)
}

/// The distance of the origin from the segment `p`-`q` (a point where they are equal).
fn segment_distance(p: V, q: V) -> f64 {
    let pq = sub(q, p);
    let len2 = dot(pq, pq);
    let s = if len2 > 0.0 { (-dot(p, pq) / len2).clamp(0.0, 1.0) } else { 0.0 };
    let x = [p[0] + s * pq[0], p[1] + s * pq[1], p[2] + s * pq[2]];
    dot(x, x).sqrt()
}

/// The sine of the angle between `ray` and `tri`'s plane (`|cos|` of the angle with its normal):
/// 1 head-on, towards 0 at a graze; `None` for a degenerate triangle or direction.
pub fn incidence(ray: &Ray, tri: &Triangle) -> Option<f64> {
    let d = v64(ray.dir);
    let [a, b, c] = tri.v.map(|p| v64(p.to_array()));
    let n = cross(sub(b, a), sub(c, a));
    let len = |p: V| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    let s = dot(n, d).abs() / (len(n) * len(d));
    s.is_finite().then_some(s)
}

fn cross(p: V, q: V) -> V {
    [p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]]
}

fn dot(p: V, q: V) -> f64 {
    p[0] * q[0] + p[1] * q[1] + p[2] * q[2]
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn decides_clear_cases_and_defers_edges() {
        let tri = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let down = |x: f32, y: f32| Ray::new(Vec3::new(x, y, 3.0), Vec3::NEG_Z, 0.0, f32::INFINITY);
        assert!(matches!(filter(&down(0.2, 0.2), &tri), Filtered::Hit { lo, hi } if lo <= 3.0 && hi >= 3.0));
        assert_eq!(filter(&down(0.9, 0.9), &tri), Filtered::Miss);
        assert!(matches!(filter(&down(0.5, 0.5), &tri), Filtered::Unsure { .. }));
        // Nearest edge: the hypotenuse, at (1 - 0.75) / sqrt(2).
        assert!((margin(&down(0.25, 0.5), &tri).unwrap() - 0.25 / 2f64.sqrt()).abs() < 1e-12);
        assert!(margin(&down(2.0, 0.5), &tri).unwrap() < 0.0);
        assert_eq!(incidence(&down(0.2, 0.2), &tri), Some(1.0));
    }

    #[test]
    fn a_graze_shrinks_the_margin_across_the_ray() {
        // The ray crosses the plane z = 0 at (0.25, 0.25) at a slope of 1 in 100, heading +x:
        // in the plane the nearest edge is 0.25 away (x = 0 and y = 0), but across the ray the
        // edge x = 0 is foreshortened by the sine, about 0.01.
        let tri = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let dir = Vec3::new(1.0, 0.0, -0.01);
        let ray = Ray::new(Vec3::new(0.25, 0.25, 0.0) - dir * 2.0, dir, 0.0, f32::INFINITY);
        let sine = incidence(&ray, &tri).unwrap();
        assert!((sine - 0.01 / 1.00005f64.sqrt()).abs() < 1e-6);
        let m = margin(&ray, &tri).unwrap();
        assert!((m - 0.25 * sine).abs() < 1e-6, "{m}");
    }
}
