//! How a method's answer is judged against the exact one.
//!
//! A floating-point method computes with the ray and triangles rounded, so where the exact ray
//! passes within rounding distance of an edge it may find the neighbour across that edge, or
//! nothing at a silhouette. The one tolerance is [`Tolerance`]: `delta`, a distance of
//! `64 * 2^-24` times the scene's largest coordinate magnitude (the watertight test's own error,
//! a few ulps of the scene's coordinates, with room to spare), and a `t` tolerance derived from
//! it. It does not grow with the origin's distance, so a ray from far away must be answered as
//! accurately as one from inside the scene. A method's answer is:
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
use super::filter::margin;
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

    /// The `t` tolerance of `ray` around `t`: `delta` along the ray plus `2^-18` of `t` (the
    /// rounding of `t` itself).
    pub fn t(&self, ray: &Ray, t: f64) -> f64 {
        let d = ray.dir.iter().fold(0.0f64, |m, x| m.max(f64::from(x.abs())));
        4.0 * self.delta / d + t.abs() / 262_144.0
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
        return if (t - best).abs() <= tol.t(ray, best) {
            Judgement::Exact
        } else {
            Judgement::Disagree(format!("primitive {} at t = {t:e}, exactly {best:e}", hit.prim))
        };
    }
    let near_p = margin(ray, tri).is_some_and(|m| m >= -tol.delta);
    let pt = plane_t(ray, tri);
    if !near_p || (pt - t).abs() > tol.t(ray, t) {
        return Judgement::Disagree(format!(
            "primitive {} at t = {t:e}, which the ray does not meet there; exactly {:?} at {best:e}",
            hit.prim, exact.winners
        ));
    }
    let skipped = exact.hits.iter().filter(|h| h.hi < t - tol.t(ray, t)).find(|h| !marginal(h.prim));
    match skipped {
        None => Judgement::Near,
        Some(h) => Judgement::Disagree(format!(
            "primitive {} at t = {t:e}, but primitive {} is hit well inside at t <= {:e}",
            hit.prim, h.prim, h.hi
        )),
    }
}
