//! An instance's placement: an affine map from its mesh's frame to the world, and the inverse
//! that takes rays the other way.
//!
//! A ray `o + t d` in the world is `A⁻¹(o − b) + t A⁻¹d` in the mesh's frame, with the same `t`
//! (the direction is mapped by the linear part alone and not renormalized), so hits of
//! different instances compare by `t` as they are.

use crate::{Aabb, Ray};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// An affine map `p ↦ A p + b` from a mesh's frame to the world, as three rows `[A | b]`
/// (row-major 3x4, the layout Embree calls `FLOAT3X4_ROW_MAJOR`).
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct Transform {
    /// Row `i` is `[A_i0, A_i1, A_i2, b_i]`.
    pub rows: [[f32; 4]; 3],
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The map that leaves every point where it is.
    pub const IDENTITY: Transform =
        Transform { rows: [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]] };

    /// The map with rows `[A | b]`.
    pub const fn from_rows(rows: [[f32; 4]; 3]) -> Self {
        Self { rows }
    }

    /// A move by `b`.
    pub const fn translation(b: [f32; 3]) -> Self {
        Self { rows: [[1.0, 0.0, 0.0, b[0]], [0.0, 1.0, 0.0, b[1]], [0.0, 0.0, 1.0, b[2]]] }
    }

    /// A scaling by `s` along the axes, about the origin.
    pub const fn scale(s: [f32; 3]) -> Self {
        Self { rows: [[s[0], 0.0, 0.0, 0.0], [0.0, s[1], 0.0, 0.0], [0.0, 0.0, s[2], 0.0]] }
    }

    /// The map of a glam affine transform.
    pub fn from_affine(m: glam::Affine3A) -> Self {
        let (a, b) = (m.matrix3, m.translation);
        let row = |i: usize| [a.col(0)[i], a.col(1)[i], a.col(2)[i], b[i]];
        Self { rows: [row(0), row(1), row(2)] }
    }

    /// `self` after `first`: the map `p ↦ self(first(p))`, in `f64` and rounded once.
    pub fn then_after(&self, first: &Transform) -> Transform {
        let (s, f) = (self.f64_rows(), first.f64_rows());
        let rows = core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                let mut x = if j == 3 { s[i][3] } else { 0.0 };
                for (k, fk) in f.iter().enumerate() {
                    x += s[i][k] * fk[j];
                }
                x as f32
            })
        });
        Transform { rows }
    }

    /// Whether every entry is finite and `A` is invertible in `f64` (a zero determinant maps the
    /// mesh onto a plane or a line, where no ray can be taken back).
    pub fn is_invertible(&self) -> bool {
        self.inverse().is_some()
    }

    /// `A p + b` in `f64` (each product of two `f32`s exact, the sums rounded).
    pub fn apply(&self, p: [f32; 3]) -> [f64; 3] {
        let r = self.f64_rows();
        let p = p.map(f64::from);
        core::array::from_fn(|i| r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2] + r[i][3])
    }

    /// The box of the mapped corners of `b`, rounded outward to `f32` and grown by `2^-16` of
    /// its size and magnitude: a superset of where a ray mapped back into the mesh's frame (with
    /// its rounding) can meet the mesh. Empty for an empty box.
    pub fn world_box(&self, b: &Aabb) -> Aabb {
        if b.is_empty() {
            return Aabb::EMPTY;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for corner in 0..8 {
            let pick = |axis: usize| if corner >> axis & 1 == 0 { b.min[axis] } else { b.max[axis] };
            let p = self.apply([pick(0), pick(1), pick(2)]);
            for i in 0..3 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        let grow = |i: usize| (hi[i] - lo[i] + lo[i].abs().max(hi[i].abs())) / 65_536.0;
        let down = |x: f64| next_f32_down(x);
        let up = |x: f64| -next_f32_down(-x);
        Aabb::new(
            Vec3::new(down(lo[0] - grow(0)), down(lo[1] - grow(1)), down(lo[2] - grow(2))),
            Vec3::new(up(hi[0] + grow(0)), up(hi[1] + grow(1)), up(hi[2] + grow(2))),
        )
    }

    fn f64_rows(&self) -> [[f64; 4]; 3] {
        self.rows.map(|r| r.map(f64::from))
    }

    /// The inverse map, or `None` where an entry is not finite or `A` is singular.
    pub(crate) fn inverse(self) -> Option<ToObject> {
        let r = self.f64_rows();
        if !r.iter().flatten().all(|x| x.is_finite()) {
            return None;
        }
        let a = |i: usize, j: usize| r[i][j];
        // The cofactors of A: A⁻¹ = adj(A) / det(A).
        let c = [
            [
                a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1),
                a(0, 2) * a(2, 1) - a(0, 1) * a(2, 2),
                a(0, 1) * a(1, 2) - a(0, 2) * a(1, 1),
            ],
            [
                a(1, 2) * a(2, 0) - a(1, 0) * a(2, 2),
                a(0, 0) * a(2, 2) - a(0, 2) * a(2, 0),
                a(0, 2) * a(1, 0) - a(0, 0) * a(1, 2),
            ],
            [
                a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0),
                a(0, 1) * a(2, 0) - a(0, 0) * a(2, 1),
                a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0),
            ],
        ];
        let det = a(0, 0) * c[0][0] + a(0, 1) * c[1][0] + a(0, 2) * c[2][0];
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let m = c.map(|row| row.map(|x| x / det));
        if !m.iter().flatten().all(|x| x.is_finite()) {
            return None;
        }
        Some(ToObject { m, b: [r[0][3], r[1][3], r[2][3]] })
    }
}

/// The largest `f32` not above `x` (`x` finite).
fn next_f32_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) <= x {
        y
    } else if y == 0.0 {
        -f32::from_bits(1)
    } else if y > 0.0 {
        f32::from_bits(y.to_bits() - 1)
    } else {
        f32::from_bits(y.to_bits() + 1)
    }
}

/// The inverse of a [`Transform`] in `f64`: world rays into the mesh's frame.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ToObject {
    /// `A⁻¹`.
    m: [[f64; 3]; 3],
    /// `b`.
    b: [f64; 3],
}

impl ToObject {
    /// `ray` in the mesh's frame: origin `A⁻¹(o − b)`, direction `A⁻¹d`, the same interval, each
    /// component rounded once to `f32`.
    pub(crate) fn ray(&self, ray: &Ray) -> Ray {
        let mul = |v: [f64; 3]| -> [f32; 3] {
            core::array::from_fn(|i| (self.m[i][0] * v[0] + self.m[i][1] * v[1] + self.m[i][2] * v[2]) as f32)
        };
        let o = core::array::from_fn(|i| f64::from(ray.origin[i]) - self.b[i]);
        Ray { origin: mul(o), tmin: ray.tmin, dir: mul(ray.dir.map(f64::from)), tmax: ray.tmax }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rotation_scale_move() -> Transform {
        let m = glam::Affine3A::from_scale_rotation_translation(
            Vec3::new(2.0, 0.5, -1.5),
            glam::Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
            Vec3::new(10.0, -3.0, 0.25),
        );
        Transform::from_affine(m)
    }

    #[test]
    fn a_ray_mapped_back_meets_the_mapped_point_at_the_same_t() {
        let m = rotation_scale_move();
        let inv = m.inverse().unwrap();
        // A point p of the mesh, mapped to the world, and a world ray through it at t = 2.
        let p = [0.3f32, -0.7, 0.2];
        let w = m.apply(p);
        let d = [0.25f32, -1.0, 0.5];
        let o = core::array::from_fn(|i| (w[i] - 2.0 * f64::from(d[i])) as f32);
        let r = inv.ray(&Ray { origin: o, tmin: 0.0, dir: d, tmax: f32::INFINITY });
        for (i, &want) in p.iter().enumerate() {
            let at = f64::from(r.origin[i]) + 2.0 * f64::from(r.dir[i]);
            assert!((at - f64::from(want)).abs() < 1e-5, "axis {i}: {at} against {want}");
        }
    }

    #[test]
    fn the_world_box_holds_every_mapped_vertex() {
        let m = rotation_scale_move();
        let b = Aabb::new(Vec3::new(-1.0, -2.0, 0.5), Vec3::new(3.0, 0.0, 0.75));
        let w = m.world_box(&b);
        for corner in 0..8 {
            let pick = |axis: usize| if corner >> axis & 1 == 0 { b.min[axis] } else { b.max[axis] };
            let p = m.apply([pick(0), pick(1), pick(2)]);
            for i in 0..3 {
                assert!(f64::from(w.min[i]) < p[i] && p[i] < f64::from(w.max[i]), "{p:?} outside {w:?}");
            }
        }
    }

    #[test]
    fn singular_and_non_finite_maps_have_no_inverse() {
        assert!(Transform::IDENTITY.is_invertible());
        assert!(!Transform::scale([1.0, 0.0, 1.0]).is_invertible());
        let mut m = Transform::IDENTITY;
        m.rows[1][3] = f32::NAN;
        assert!(!m.is_invertible());
        // Rows 0 and 2 equal: rank 2.
        assert!(
            !Transform::from_rows([[1.0, 2.0, 3.0, 0.0], [0.0, 1.0, 0.0, 0.0], [1.0, 2.0, 3.0, 5.0]]).is_invertible()
        );
    }

    #[test]
    fn composing_with_the_identity_changes_nothing() {
        let m = rotation_scale_move();
        assert_eq!(m.then_after(&Transform::IDENTITY), m);
        assert_eq!(Transform::IDENTITY.then_after(&m), m);
    }
}
