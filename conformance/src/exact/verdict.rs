//! How a method's answer is judged against the exact one.
//!
//! A floating-point method computes with the ray and triangles rounded, so where the exact ray
//! passes within rounding distance of an edge it may find the neighbour across that edge, or
//! nothing at a silhouette. The one tolerance is [`Tolerance`]: `delta`, a distance of
//! `64 * 2^-24` times the scene's largest coordinate magnitude (the watertight test's own error,
//! a few ulps of the scene's coordinates, with room to spare), measured across the ray, where the
//! watertight test decides (see [`margin`]), and a `t` tolerance derived from it: a shift of
//! `delta` across the ray moves a triangle's `t` by `delta / sin` of the angle between the ray
//! and the triangle's plane, so a grazing hit earns a wider `t` window. It does not grow with the
//! origin's distance, so a ray from far away must be answered as accurately as one from inside
//! the scene. A method's answer is:
//! - **exact**: a winner of [`ExactAnswer`] at a `t` within the tolerance, or a miss where the
//!   ray hits nothing;
//! - **near**: a triangle the ray passes within `delta` of, at its `t`, where every triangle the
//!   ray hits before it is hit within `delta` of its boundary; or a miss where every triangle the
//!   ray hits is hit within `delta` of its boundary (never for a ray that must hit: from inside a
//!   closed mesh);
//! - **refused**: [`Hit::REFUSED`](raytrail_core::Hit::REFUSED), the method's explicit "cannot
//!   answer";
//! - **disagreeing**: anything else.

use super::closest::ExactAnswer;
use super::filter::{incidence, margin};
use raytrail_core::geometry::Triangle;
use raytrail_core::{Hit, Ray};

/// The tolerance of [`judge`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// A distance in scene units.
    pub delta: f64,
}

impl Tolerance {
    /// Multiples of `2^-24` of the scene's largest coordinate magnitude in `delta`.
    pub const ULPS: f64 = 64.0;

    /// The tolerance for a scene whose largest coordinate magnitude is `scene_scale`.
    pub fn for_scene(scene_scale: f32) -> Self {
        Self { delta: Self::ULPS * f64::from(scene_scale) / 16_777_216.0 }
    }

    /// The `t` tolerance of `ray` on `tri` around `t`: how far `delta` across the ray moves the
    /// crossing with `tri`'s plane (`delta / sin` of the angle between them, four times over),
    /// plus `2^-18` of `t` (the rounding of `t` itself). Infinite for a ray parallel to `tri`,
    /// whose `t` no shift pins down.
    pub fn t(&self, ray: &Ray, tri: &Triangle, t: f64) -> f64 {
        let d = ray.dir.iter().fold(0.0f64, |m, x| m.max(f64::from(x.abs())));
        let sine = incidence(ray, tri).unwrap_or(0.0);
        4.0 * self.delta / (d * sine) + t.abs() / 262_144.0
    }
}

/// The judgement of one answer.
#[derive(Clone, Debug, PartialEq)]
pub enum Judgement {
    /// The exact answer.
    Exact,
    /// An answer within the tolerance (see the module docs).
    Near,
    /// The method refused the ray.
    Refused,
    /// A wrong answer, and why.
    Disagree(String),
}

/// The plane `t` of `tri` along `ray`, in `f64` (where a method's `t` on `tri` is judged).
pub fn plane_t(ray: &Ray, tri: &Triangle) -> f64 {
    let v = |p: [f32; 3]| p.map(f64::from);
    let [a, b, c] = tri.v.map(|p| v(p.to_array()));
    let (o, d) = (v(ray.origin), v(ray.dir));
    let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
    let dot = |p: [f64; 3], q: [f64; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    dot(n, [a[0] - o[0], a[1] - o[1], a[2] - o[2]]) / dot(n, d)
}

/// The distance of `ray`'s point at `t` from `tri` (in `f32`, a tolerance's precision).
fn point_distance(ray: &Ray, tri: &Triangle, t: f64) -> f64 {
    let at = |i: usize| (f64::from(ray.origin[i]) + t * f64::from(ray.dir[i])) as f32;
    let p = glam::Vec3::new(at(0), at(1), at(2));
    let near = raytrail_core::nearest::closest_point_on_triangle(p, tri.v[0], tri.v[1], tri.v[2]);
    f64::from(near.distance2).sqrt()
}

/// Judges `hit`, a method's answer for `ray`, against `exact`; `must_hit` for a ray that cannot
/// miss (from inside a closed mesh).
pub fn judge(
    ray: &Ray,
    triangles: &[Triangle],
    exact: &ExactAnswer,
    hit: &Hit,
    tol: Tolerance,
    must_hit: bool,
) -> Judgement {
    if hit.is_refused() {
        return Judgement::Refused;
    }
    let marginal = |prim: u32| margin(ray, &triangles[prim as usize]).is_none_or(|m| m <= tol.delta);
    if !hit.is_hit() {
        return if exact.hits.is_empty() {
            Judgement::Exact
        } else if must_hit {
            Judgement::Disagree(format!("a miss, but the ray must hit (closest: {:?})", exact.winners))
        } else if exact.hits.iter().all(|h| marginal(h.prim)) {
            Judgement::Near
        } else {
            Judgement::Disagree(format!("a miss, but it hits {:?} at t = {:e}", exact.winners, exact.t_f64()))
        };
    }
    let Some(tri) = triangles.get(hit.prim as usize) else {
        return Judgement::Disagree(format!("primitive {} does not exist", hit.prim));
    };
    let t = f64::from(hit.t);
    if !t.is_finite() {
        return Judgement::Disagree(format!("a hit at t = {t}"));
    }
    let best = exact.t_f64();
    if exact.winners.contains(&hit.prim) {
        return if (t - best).abs() <= tol.t(ray, tri, best) {
            Judgement::Exact
        } else {
            Judgement::Disagree(format!("primitive {} at t = {t:e}, exactly {best:e}", hit.prim))
        };
    }
    let near_p = margin(ray, tri).is_some_and(|m| m >= -tol.delta);
    let pt = plane_t(ray, tri);
    let window = tol.t(ray, tri, t);
    // A ray in the triangle's plane crosses it over a stretch of `t` that the plane does not pin
    // down: there the point at `t` itself must lie on the triangle, within the tolerance.
    let on_triangle = window.is_finite() || point_distance(ray, tri, t) <= 4.0 * tol.delta + t.abs() / 262_144.0;
    if !near_p || !on_triangle || (pt - t).abs() > window {
        return Judgement::Disagree(format!(
            "primitive {} at t = {t:e}, which the ray does not meet there; exactly {:?} at {best:e}",
            hit.prim, exact.winners
        ));
    }
    // A triangle hit well inside, so far before `t` that its own tolerance cannot bridge the gap,
    // was skipped.
    let skipped = exact
        .hits
        .iter()
        .filter(|h| triangles.get(h.prim as usize).is_some_and(|tri| h.hi < t - tol.t(ray, tri, h.hi)))
        .find(|h| !marginal(h.prim));
    match skipped {
        None => Judgement::Near,
        Some(h) => Judgement::Disagree(format!(
            "primitive {} at t = {t:e}, but primitive {} is hit well inside at t <= {:e}",
            hit.prim, h.prim, h.hi
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::super::closest::closest_hit;
    use super::*;
    use glam::Vec3;

    /// A ray sloping down by `slope` along +x that crosses the plane z = 0 at `(x, 0.25)`.
    fn graze(x: f32, slope: f32) -> Ray {
        let dir = Vec3::new(1.0, 0.0, -slope);
        Ray::new(Vec3::new(x, 0.25, 0.0) - dir * 2.0, dir, 0.0, f32::INFINITY)
    }

    fn verdict(ray: &Ray, tris: &[Triangle], prim: u32) -> Judgement {
        let hit = Hit { t: plane_t(ray, &tris[prim as usize]) as f32, prim, u: 0.0, v: 0.0 };
        judge(ray, tris, &closest_hit(ray, tris), &hit, Tolerance::for_scene(1.0), false)
    }

    #[test]
    fn a_graze_is_judged_across_the_ray() {
        let tris = [Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
        let (delta, slope) = (Tolerance::for_scene(1.0).delta as f32, 1e-3);
        assert_eq!(verdict(&graze(0.25, slope), &tris, 0), Judgement::Exact);
        // Outside the edge x = 0 by half of `delta` across the ray: 500 times that in the plane,
        // which a rounding across the ray explains.
        assert_eq!(verdict(&graze(-0.5 * delta / slope, slope), &tris, 0), Judgement::Near);
        // Four times `delta` across the ray: no rounding explains it.
        assert!(matches!(verdict(&graze(-4.0 * delta / slope, slope), &tris, 0), Judgement::Disagree(_)));
    }

    #[test]
    fn a_grazing_hit_does_not_excuse_skipping_a_face_in_front() {
        // Face 1 stands across the ray at x = 0.1, head-on; face 0 is grazed behind it.
        let wall = Triangle::new(Vec3::new(0.1, -1.0, -1.0), Vec3::new(0.1, 2.0, -1.0), Vec3::new(0.1, 0.0, 2.0));
        let tris = [Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y), wall];
        let ray = graze(0.25, 1e-3);
        assert_eq!(verdict(&ray, &tris, 1), Judgement::Exact);
        assert!(matches!(verdict(&ray, &tris, 0), Judgement::Disagree(_)));
    }

    #[test]
    fn a_ray_in_a_triangles_plane_may_hit_it_only_where_it_crosses_it() {
        // The ray runs along y = 0.25 in the plane z = 0 and crosses the triangle for x in
        // [0, 0.75], t in [2, 2.75]: a rounded copy of the ray may hit it there, nowhere else.
        let tris = [Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
        let ray = Ray::new(Vec3::new(-2.0, 0.25, 0.0), Vec3::X, 0.0, f32::INFINITY);
        let at = |t: f32| Hit { t, prim: 0, u: 0.0, v: 0.0 };
        let judge_at =
            |ray: &Ray, t| judge(ray, &tris, &closest_hit(ray, &tris), &at(t), Tolerance::for_scene(1.0), false);
        assert_eq!(judge_at(&ray, 2.5), Judgement::Near);
        assert!(matches!(judge_at(&ray, 3.5), Judgement::Disagree(_)));
        // Parallel to the plane, four times `delta` above it: no rounding brings it there.
        let above = Ray { origin: [-2.0, 0.25, 4.0 * Tolerance::for_scene(1.0).delta as f32], ..ray };
        assert!(matches!(judge_at(&above, 2.5), Judgement::Disagree(_)));
    }
}
