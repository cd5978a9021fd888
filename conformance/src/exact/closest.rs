//! The brute force: every triangle, the filter first, the exact test where it is in doubt, and
//! the closest hit compared exactly.

use super::filter::{filter, Filtered};
use super::triangle::{exact_hit, ExactT};
use raytrail_core::geometry::Triangle;
use raytrail_core::Ray;
use std::cmp::Ordering;

/// One triangle the ray certainly hits, with bounds on its `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnyHit {
    /// Primitive id.
    pub prim: u32,
    /// Lower bound on the exact `t`.
    pub lo: f64,
    /// Upper bound on the exact `t`.
    pub hi: f64,
}

/// The exact answer for one ray (see the module [`super`] for the definition).
#[derive(Clone, Debug, PartialEq)]
pub struct ExactAnswer {
    /// The closest `t`, exactly; `None` for a ray that hits nothing (or is not traceable).
    pub t: Option<ExactT>,
    /// Every primitive hit at exactly that `t`, ascending (the first is the tie rule's answer).
    pub winners: Vec<u32>,
    /// Every triangle the ray hits, with bounds on its `t`.
    pub hits: Vec<AnyHit>,
}

impl ExactAnswer {
    /// The answer for a ray that hits nothing.
    pub fn miss() -> Self {
        Self { t: None, winners: Vec::new(), hits: Vec::new() }
    }

    /// The closest `t` as `f64` (infinite for a miss).
    pub fn t_f64(&self) -> f64 {
        self.t.as_ref().map_or(f64::INFINITY, ExactT::to_f64)
    }
}

/// The exact closest hit of `ray` among `triangles` (primitive ids are indices).
pub fn closest_hit(ray: &Ray, triangles: &[Triangle]) -> ExactAnswer {
    closest_among(ray, triangles, 0..triangles.len() as u32)
}

/// The exact closest hit of `ray` among the `candidates` of `triangles` (ascending ids; ids out
/// of range are skipped). It equals [`closest_hit`] whenever no triangle left out of
/// `candidates` is hit: what a conservative culling ([`super::accel`]) guarantees.
pub fn closest_among(ray: &Ray, triangles: &[Triangle], candidates: impl IntoIterator<Item = u32>) -> ExactAnswer {
    if !ray.is_traceable() {
        return ExactAnswer::miss();
    }
    let mut hits = Vec::new();
    for prim in candidates {
        let Some(tri) = triangles.get(prim as usize) else { continue };
        match filter(ray, tri) {
            Filtered::Miss => {}
            Filtered::Hit { lo, hi } => hits.push(AnyHit { prim, lo, hi }),
            Filtered::Unsure { lo, hi } => {
                if let Some(t) = exact_hit(ray, tri) {
                    let x = t.to_f64();
                    // The filter's interval may be unknown (the plane test was in doubt).
                    let (lo, hi) = if lo.is_finite() && hi.is_finite() { (lo, hi) } else { (x, x) };
                    hits.push(AnyHit { prim, lo: lo.min(x), hi: hi.max(x) });
                }
            }
        }
    }
    let Some(best_hi) = hits.iter().map(|h| h.hi).min_by(f64::total_cmp) else {
        return ExactAnswer::miss();
    };
    // Only triangles whose interval reaches below every certain upper bound can be closest.
    let mut best: Option<ExactT> = None;
    let mut winners = Vec::new();
    for h in hits.iter().filter(|h| h.lo <= best_hi) {
        let Some(t) = exact_hit(ray, &triangles[h.prim as usize]) else {
            continue;
        };
        match best.as_ref().map(|b| t.cmp_exact(b)) {
            None | Some(Ordering::Less) => {
                best = Some(t);
                winners = vec![h.prim];
            }
            Some(Ordering::Equal) => winners.push(h.prim),
            Some(Ordering::Greater) => {}
        }
    }
    winners.sort_unstable();
    ExactAnswer { t: best, winners, hits }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn shared_edge_has_two_winners_and_closest_wins() {
        let tris = [
            Triangle::new(Vec3::new(0.0, 0.0, -1.0), Vec3::new(1.0, 0.0, -1.0), Vec3::new(1.0, 1.0, -1.0)),
            Triangle::new(Vec3::new(0.0, 0.0, -1.0), Vec3::new(1.0, 1.0, -1.0), Vec3::new(0.0, 1.0, -1.0)),
            Triangle::new(Vec3::new(-5.0, -5.0, -2.0), Vec3::new(5.0, -5.0, -2.0), Vec3::new(0.0, 5.0, -2.0)),
        ];
        let ray = Ray::new(Vec3::new(0.5, 0.5, 0.0), Vec3::NEG_Z, 0.0, f32::INFINITY);
        let a = closest_hit(&ray, &tris);
        assert_eq!(a.winners, vec![0, 1]);
        assert_eq!(a.hits.len(), 3);
        assert_eq!(a.t_f64(), 1.0);
        let b = closest_hit(&Ray { tmin: 1.5, ..ray }, &tris);
        assert_eq!(b.winners, vec![2]);
        assert_eq!(b.t_f64(), 2.0);
    }
}
