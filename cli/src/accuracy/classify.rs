//! How one method's answer to one ray is classified against the exact reference, and the tally
//! of a sample.
//!
//! Closest-hit answers are judged by the exact reference's own verdict
//! ([`raytrail_conformance::exact::verdict`]: exact ties, and the one rounding tolerance
//! `delta` near edges, are no error); a disagreement is then split by what is wrong:
//! - **false miss**: the method misses, the ray hits a triangle well inside it;
//! - **false hit**: the method hits, the ray hits nothing (and passes no triangle within `delta`);
//! - **wrong primitive**: the method names a triangle that is not the closest (nor within `delta`
//!   of the ray before any triangle hit well inside), while the ray does hit something;
//! - **bad `t`**: the right triangle at a `t` beyond the tolerance.
//!
//! Any-hit answers (shadow and ambient-occlusion rays) need not be the closest: a named triangle
//! the ray hits is right, at that triangle's exact `t`; a triangle the ray only passes within
//! `delta` of is near; a triangle the ray does not meet is a wrong primitive when the ray is
//! occluded anyway (the verdict "occluded" is right, its witness is not) and a false hit
//! otherwise.
//!
//! The `t` error is counted in ulps of `f32` at the exact `t` (rounded to `f64` first, which adds
//! under `2^-29` ulps) for every answer naming a triangle the ray hits.

use raytrail::core::geometry::Triangle;
use raytrail::core::method::Query;
use raytrail::core::{Hit, Ray};
use raytrail_conformance::exact::triangle::exact_hit;
use raytrail_conformance::exact::{judge, ExactAnswer, Judgement, Tolerance};
use serde::Serialize;

/// What one answer is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// The exact answer (a winner, `t` within the tolerance; or a true miss).
    Exact,
    /// Within the rounding tolerance of the exact answer.
    Near,
    /// The method refused the ray.
    Refused,
    /// A miss where the ray hits.
    FalseMiss,
    /// A hit where the ray hits nothing.
    FalseHit,
    /// The wrong triangle.
    WrongPrim,
    /// The right triangle at a wrong `t`.
    BadT,
}

/// `|t - exact|` in ulps of `f32` at `exact`; `None` unless both are finite.
pub fn ulps(t: f32, exact: f64) -> Option<f64> {
    if !t.is_finite() || !exact.is_finite() {
        return None;
    }
    let e = (exact as f32).abs();
    let ulp = if e == f32::MAX { 2f64.powi(104) } else { f64::from(f32::from_bits(e.to_bits() + 1)) - f64::from(e) };
    Some((f64::from(t) - exact).abs() / ulp)
}

/// Classifies `hit`, a method's answer with `query` for `ray`, against `exact` (the exact
/// closest-hit answer); returns the class and the `t` error in ulps where the answer names a
/// triangle the ray hits.
pub fn classify(
    query: Query,
    ray: &Ray,
    triangles: &[Triangle],
    exact: &ExactAnswer,
    hit: &Hit,
    tol: Tolerance,
) -> (Class, Option<f64>) {
    if hit.is_refused() {
        return (Class::Refused, None);
    }
    let (judgement, err) = match query {
        Query::Closest => {
            let err = if hit.is_hit() && exact.winners.contains(&hit.prim) { ulps(hit.t, exact.t_f64()) } else { None };
            (judge(ray, triangles, exact, hit, tol, false), err)
        }
        Query::Any if !hit.is_hit() => (judge(ray, triangles, exact, hit, tol, false), None),
        Query::Any => {
            // Judge the named triangle as if it were the only one: hit, it is the answer.
            let t = exact
                .hits
                .iter()
                .any(|h| h.prim == hit.prim)
                .then(|| triangles.get(hit.prim as usize).and_then(|tri| exact_hit(ray, tri)));
            let own = match t.flatten() {
                Some(t) => ExactAnswer { t: Some(t), winners: vec![hit.prim], hits: Vec::new() },
                None => ExactAnswer::miss(),
            };
            let err = own.t.as_ref().and_then(|_| ulps(hit.t, own.t_f64()));
            (judge(ray, triangles, &own, hit, tol, false), err)
        }
    };
    let class = match judgement {
        Judgement::Exact => Class::Exact,
        Judgement::Near => Class::Near,
        Judgement::Refused => Class::Refused,
        Judgement::Disagree(_) if !hit.is_hit() => Class::FalseMiss,
        Judgement::Disagree(_) if exact.hits.is_empty() => Class::FalseHit,
        Judgement::Disagree(_) if err.is_some() => Class::BadT,
        Judgement::Disagree(_) => Class::WrongPrim,
    };
    (class, err)
}

/// The tally of one method on one sample.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Tally {
    /// Rays judged.
    pub rays: usize,
    /// Exact answers.
    pub exact: usize,
    /// Answers within the tolerance.
    pub near: usize,
    /// Refused rays.
    pub refused: usize,
    /// False misses.
    pub false_misses: usize,
    /// False hits.
    pub false_hits: usize,
    /// Wrong primitives.
    pub wrong_prims: usize,
    /// Right primitives at a `t` beyond the tolerance.
    pub bad_t: usize,
    /// Largest `t` error in ulps (0 with no hit).
    pub t_ulps_max: f64,
    /// Mean `t` error in ulps over the answers naming a triangle the ray hits.
    pub t_ulps_mean: f64,
    /// Answers the `t` error was taken over.
    pub t_count: usize,
}

impl Tally {
    /// Adds one answer.
    pub fn add(&mut self, (class, err): (Class, Option<f64>)) {
        self.rays += 1;
        match class {
            Class::Exact => self.exact += 1,
            Class::Near => self.near += 1,
            Class::Refused => self.refused += 1,
            Class::FalseMiss => self.false_misses += 1,
            Class::FalseHit => self.false_hits += 1,
            Class::WrongPrim => self.wrong_prims += 1,
            Class::BadT => self.bad_t += 1,
        }
        if let Some(e) = err {
            self.t_ulps_mean = (self.t_ulps_mean * self.t_count as f64 + e) / (self.t_count + 1) as f64;
            self.t_count += 1;
            self.t_ulps_max = self.t_ulps_max.max(e);
        }
    }

    /// Wrong answers: false misses, false hits, wrong primitives and bad `t`.
    pub fn errors(&self) -> usize {
        self.false_misses + self.false_hits + self.wrong_prims + self.bad_t
    }

    /// Wrong answers as a share of the rays judged.
    pub fn error_rate(&self) -> f64 {
        self.errors() as f64 / self.rays.max(1) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use raytrail_conformance::exact::closest_hit;

    /// Two unit squares at z = -1 (triangles 0, 1, sharing the diagonal) and a big triangle
    /// below them at z = -2 (2).
    fn scene() -> Vec<Triangle> {
        let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        vec![
            Triangle::new(p(0.0, 0.0, -1.0), p(1.0, 0.0, -1.0), p(1.0, 1.0, -1.0)),
            Triangle::new(p(0.0, 0.0, -1.0), p(1.0, 1.0, -1.0), p(0.0, 1.0, -1.0)),
            Triangle::new(p(-5.0, -5.0, -2.0), p(5.0, -5.0, -2.0), p(0.0, 5.0, -2.0)),
        ]
    }

    fn down(x: f32, y: f32) -> Ray {
        Ray::new(Vec3::new(x, y, 0.0), Vec3::NEG_Z, 0.0, f32::INFINITY)
    }

    fn hit(t: f32, prim: u32) -> Hit {
        Hit { t, prim, u: 0.0, v: 0.0 }
    }

    fn class(q: Query, ray: &Ray, h: Hit) -> (Class, Option<f64>) {
        let tris = scene();
        classify(q, ray, &tris, &closest_hit(ray, &tris), &h, Tolerance::for_scene(5.0))
    }

    #[test]
    fn right_answers_and_ties_are_no_error() {
        let inside = down(0.7, 0.2);
        assert_eq!(class(Query::Closest, &inside, hit(1.0, 0)), (Class::Exact, Some(0.0)));
        // Through the shared diagonal both triangles are winners.
        let edge = down(0.5, 0.5);
        assert_eq!(class(Query::Closest, &edge, hit(1.0, 0)).0, Class::Exact);
        assert_eq!(class(Query::Closest, &edge, hit(1.0, 1)).0, Class::Exact);
        // Any hit: the farther triangle is a right answer too.
        assert_eq!(class(Query::Any, &inside, hit(2.0, 2)), (Class::Exact, Some(0.0)));
        assert_eq!(class(Query::Any, &down(9.0, 9.0), Hit::MISS), (Class::Exact, None));
        assert_eq!(class(Query::Closest, &inside, Hit::REFUSED), (Class::Refused, None));
    }

    #[test]
    fn deliberately_wrong_answers_are_counted() {
        let inside = down(0.7, 0.2);
        // Skipping the closest triangle for the one behind it.
        assert_eq!(class(Query::Closest, &inside, hit(2.0, 2)).0, Class::WrongPrim);
        // The neighbour across the diagonal, far from it: wrong.
        assert_eq!(class(Query::Closest, &inside, hit(1.0, 1)).0, Class::WrongPrim);
        assert_eq!(class(Query::Closest, &inside, Hit::MISS).0, Class::FalseMiss);
        assert_eq!(class(Query::Any, &inside, Hit::MISS).0, Class::FalseMiss);
        // Nothing there: a hit is false.
        assert_eq!(class(Query::Closest, &down(9.0, 9.0), hit(1.0, 0)).0, Class::FalseHit);
        assert_eq!(class(Query::Any, &down(9.0, 9.0), hit(2.0, 2)).0, Class::FalseHit);
        // The right triangle, `t` off by a lot; a few ulps off is within the tolerance.
        let (c, e) = class(Query::Closest, &inside, hit(1.25, 0));
        assert_eq!(c, Class::BadT);
        assert_eq!(e, Some(0.25 / f64::from(f32::EPSILON)));
        let (c, e) = class(Query::Closest, &inside, hit(1.0 + 2.0 * f32::EPSILON, 0));
        assert_eq!((c, e), (Class::Exact, Some(2.0)));
        assert_eq!(class(Query::Any, &inside, hit(3.0, 2)).0, Class::BadT);
        // Occluded, but the named triangle is not on the ray: its witness is wrong.
        assert_eq!(class(Query::Any, &inside, hit(1.0, 1)).0, Class::WrongPrim);
        // A primitive id that does not exist.
        assert_eq!(class(Query::Closest, &inside, hit(1.0, 77)).0, Class::WrongPrim);
    }

    #[test]
    fn the_tally_adds_up() {
        let mut t = Tally::default();
        for c in [(Class::Exact, Some(1.0)), (Class::BadT, Some(5.0)), (Class::FalseMiss, None), (Class::Near, None)] {
            t.add(c);
        }
        assert_eq!((t.rays, t.exact, t.near, t.bad_t, t.false_misses, t.errors()), (4, 1, 1, 1, 1, 2));
        assert_eq!((t.t_ulps_max, t.t_ulps_mean, t.t_count), (5.0, 3.0, 2));
        assert_eq!(t.error_rate(), 0.5);
        assert_eq!(ulps(1.0, 1.0), Some(0.0));
        assert_eq!(ulps(f32::INFINITY, 1.0), None);
    }
}
