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

/// The signed distance (in scene units, `f64`) from where `ray` crosses `tri`'s plane to the
/// triangle's boundary: positive inside, negative outside; `None` for a ray parallel to the
/// plane or a degenerate triangle. For tolerances, not for decisions.
pub fn margin(ray: &Ray, tri: &Triangle) -> Option<f64> {
    let (o, d) = (v64(ray.origin), v64(ray.dir));
    let [a, b, c] = tri.v.map(|p| v64(p.to_array()));
    let (e1, e2, s) = (sub(b, a), sub(c, a), sub(o, a));
    let nd = d.map(|x| -x);
    let m = det(e1, e2, nd).v;
    if m == 0.0 || !m.is_finite() {
        return None;
    }
    let beta = det(s, e2, nd).v / m;
    let gamma = det(e1, s, nd).v / m;
    let alpha = 1.0 - beta - gamma;
    let len = |p: V| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    let cr = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
    let area2 = len(cr);
    if area2 == 0.0 {
        return None;
    }
    // The distance to the edge opposite a vertex is its barycentric times that vertex's altitude.
    let h = |edge: V| area2 / len(edge);
    let m = (alpha * h(sub(c, b))).min(beta * h(e2)).min(gamma * h(e1));
    m.is_finite().then_some(m)
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
    }
}
