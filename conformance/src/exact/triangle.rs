//! The exact ray/triangle test, in integers.
//!
//! With `e1 = b - a`, `e2 = c - a`, `s = o - a`, the hit `a + beta e1 + gamma e2 = o + t d`
//! solves by Cramer's rule over `M = [e1 e2 -d]`: `beta = det[s e2 -d] / det M`, `gamma =
//! det[e1 s -d] / det M`, `t = det[e1 e2 s] / det M`. Every determinant is an integer, so the
//! signs, and the comparison of `t` with the interval and with other triangles' `t`, are exact.

use super::dyadic::{to_int, to_int3};
use num_bigint::{BigInt, Sign};
use raytrail_core::geometry::Triangle;
use raytrail_core::Ray;
use std::cmp::Ordering;

/// An exact `t`: `num / den` with `den > 0`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExactT {
    /// Numerator.
    pub num: BigInt,
    /// Denominator, positive.
    pub den: BigInt,
}

impl ExactT {
    /// Exact comparison of two values.
    pub fn cmp_exact(&self, other: &ExactT) -> Ordering {
        (&self.num * &other.den).cmp(&(&other.num * &self.den))
    }

    /// The comparison with an `f32` (finite or infinite).
    pub fn cmp_f32(&self, x: f32) -> Ordering {
        if x == f32::INFINITY {
            return Ordering::Less;
        }
        if x == f32::NEG_INFINITY {
            return Ordering::Greater;
        }
        // `x * 2^149` is an integer; compare `num * 2^149` with it times `den`.
        let xi = to_int(x).unwrap_or_default();
        ((&self.num) << 149usize).cmp(&(xi * &self.den))
    }

    /// The nearest `f64` (up to the rounding of two conversions; for reports and tolerances).
    pub fn to_f64(&self) -> f64 {
        // Keep 60 significant bits of each before converting, so huge integers cannot overflow.
        let shrink = |x: &BigInt| {
            let bits = x.bits() as i64;
            let drop = (bits - 60).max(0);
            let v = (x >> drop as usize).to_string().parse::<f64>().unwrap_or(0.0);
            (v, drop)
        };
        let (n, dn) = shrink(&self.num);
        let (d, dd) = shrink(&self.den);
        n / d * 2f64.powi((dn - dd) as i32)
    }
}

fn sub(a: &[BigInt; 3], b: &[BigInt; 3]) -> [BigInt; 3] {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}

/// `x . (y x z)`.
fn det(x: &[BigInt; 3], y: &[BigInt; 3], z: &[BigInt; 3]) -> BigInt {
    let c0 = &y[1] * &z[2] - &y[2] * &z[1];
    let c1 = &y[2] * &z[0] - &y[0] * &z[2];
    let c2 = &y[0] * &z[1] - &y[1] * &z[0];
    &x[0] * c0 + &x[1] * c1 + &x[2] * c2
}

/// Signs multiply like numbers: whether `a / b >= 0` for `b != 0`.
fn same_side(a: &BigInt, b: &BigInt) -> bool {
    a.sign() == Sign::NoSign || a.sign() == b.sign()
}

/// The exact `t` at which `ray` hits the closed triangle within `[tmin, tmax]`, or `None`
/// (a miss, a ray parallel to the plane, or a non-finite input).
pub fn exact_hit(ray: &Ray, tri: &Triangle) -> Option<ExactT> {
    let o = to_int3(ray.origin)?;
    let d = to_int3(ray.dir)?;
    let [a, b, c] = [to_int3(tri.v[0].to_array())?, to_int3(tri.v[1].to_array())?, to_int3(tri.v[2].to_array())?];
    let (e1, e2, s) = (sub(&b, &a), sub(&c, &a), sub(&o, &a));
    let nd = [-&d[0], -&d[1], -&d[2]];
    let m = det(&e1, &e2, &nd);
    if m.sign() == Sign::NoSign {
        return None;
    }
    let beta = det(&s, &e2, &nd);
    let gamma = det(&e1, &s, &nd);
    let alpha = &m - &beta - &gamma;
    if !(same_side(&beta, &m) && same_side(&gamma, &m) && same_side(&alpha, &m)) {
        return None;
    }
    let num = det(&e1, &e2, &s);
    let t = if m.sign() == Sign::Minus { ExactT { num: -num, den: -m } } else { ExactT { num, den: m } };
    (t.cmp_f32(ray.tmin) != Ordering::Less && t.cmp_f32(ray.tmax) != Ordering::Greater).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn edges_and_vertices_are_inside_and_t_is_exact() {
        let tri = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let down = |x: f32, y: f32| Ray::new(Vec3::new(x, y, 3.0), Vec3::new(0.0, 0.0, -2.0), 0.0, f32::INFINITY);
        let t = exact_hit(&down(0.5, 0.5), &tri).expect("edge point");
        assert_eq!(t.cmp_f32(1.5), Ordering::Equal);
        assert!(exact_hit(&down(0.0, 0.0), &tri).is_some());
        assert!(exact_hit(&down(0.5, 0.500_000_06), &tri).is_none());
        assert!(exact_hit(&down(f32::from_bits(1), -f32::from_bits(1)), &tri).is_none());
        // The interval is inclusive, and a ray in the plane is no hit.
        let r = Ray::new(Vec3::new(0.2, 0.2, 3.0), Vec3::NEG_Z, 0.0, 3.0);
        assert!(exact_hit(&r, &tri).is_some());
        assert!(exact_hit(&Ray { tmax: 2.999_999_8, ..r }, &tri).is_none());
        assert!(exact_hit(&Ray::new(Vec3::new(-1.0, 0.2, 0.0), Vec3::X, 0.0, 9.0), &tri).is_none());
        assert!((t.to_f64() - 1.5).abs() < 1e-15);
    }
}
