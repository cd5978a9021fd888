//! How far a target's hits agree with raytrail's stack method, and why they differ where they do.

use glam::DVec3;
use raytrail::core::geometry::Triangle;
use raytrail::core::method::Query;
use raytrail::core::{Hit, Ray};
use std::collections::BTreeMap;

/// Relative tolerance under which two distances count as equal.
pub const T_TOLERANCE: f64 = 1e-5;

/// Smallest barycentric weight under which a hit point counts as on an edge or vertex.
const EDGE: f64 = 1e-4;

/// Why a hit differs from the reference (closest hit: primitive or `t`; any hit: occlusion).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Class {
    /// Both hit a different primitive at exactly the same `t` (shared edge or vertex, coplanar
    /// overlap): the tie rule differs (raytrail takes the smaller primitive id).
    TieEqualT,
    /// Both hit a different primitive with `t` within the tolerance.
    NearTie,
    /// Both hit the same primitive, `t` beyond the tolerance apart: a grazing ray or a sliver
    /// triangle, where a test computing `t` from the plane equation loses digits.
    SameTriangleFarT,
    /// The target missed (or went past) the reference's hit, which lies on an edge or vertex.
    MissOnEdge,
    /// The target hit (nearer, or where the reference misses) on an edge or vertex.
    ExtraOnEdge,
    /// The target missed the reference's hit right next to the ray's origin (closer than 1e-3 of
    /// the coordinates' magnitude): a box the ray starts on, culled by an unpadded box test.
    NearOrigin,
    /// The target missed the reference's hit on a triangle seen from its back.
    Backface,
    /// The target missed the reference's hit on a triangle whose determinant with the unit
    /// direction, `|((b - a) x (c - a)) . d / |d||` (twice its area projected across the ray), is
    /// below `f32::EPSILON`: a tiny or grazed triangle, which a Möller-Trumbore test with an
    /// absolute epsilon rejects.
    TinyDeterminant,
    /// The hit lies at an end of the ray's interval (within the tolerance).
    IntervalEnd,
    /// Anything else.
    Other,
}

impl Class {
    /// Short name for tables and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Class::TieEqualT => "tie-equal-t",
            Class::NearTie => "near-tie",
            Class::SameTriangleFarT => "same-prim-t-off",
            Class::MissOnEdge => "miss-on-edge",
            Class::ExtraOnEdge => "extra-hit-on-edge",
            Class::NearOrigin => "miss-near-origin",
            Class::Backface => "missed-backface",
            Class::TinyDeterminant => "tiny-determinant",
            Class::IntervalEnd => "interval-end",
            Class::Other => "other",
        }
    }
}

/// Agreement counts of one target on one ray set.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Agreement {
    /// Rays compared.
    pub rays: usize,
    /// Same primitive and `t` bit for bit (any hit: same occlusion).
    pub exact: usize,
    /// Same primitive and `t` within [`T_TOLERANCE`] (any hit: same occlusion); includes `exact`.
    pub close: usize,
    /// The other rays, by class.
    pub classes: BTreeMap<Class, usize>,
}

impl Agreement {
    /// Share of exact agreements, in percent.
    pub fn exact_pct(&self) -> f64 {
        100.0 * self.exact as f64 / self.rays.max(1) as f64
    }

    /// Share of agreements within the tolerance, in percent.
    pub fn close_pct(&self) -> f64 {
        100.0 * self.close as f64 / self.rays.max(1) as f64
    }
}

/// Compares `got` with `expected` (the reference's hits) ray by ray.
pub fn compare(query: Query, rays: &[Ray], expected: &[Hit], got: &[Hit], triangles: &[Triangle]) -> Agreement {
    let mut a = Agreement { rays: rays.len(), ..Agreement::default() };
    for ((ray, e), g) in rays.iter().zip(expected).zip(got) {
        let class = match query {
            Query::Closest => closest(ray, e, g, triangles),
            Query::Any => any(ray, e, g, triangles),
        };
        match class {
            Ok(exact) => {
                a.close += 1;
                a.exact += usize::from(exact);
            }
            Err(c) => *a.classes.entry(c).or_default() += 1,
        }
    }
    a
}

/// `Ok(exact)` when the closest hits agree, else why not.
fn closest(ray: &Ray, e: &Hit, g: &Hit, tris: &[Triangle]) -> Result<bool, Class> {
    if e.same_as(g) || (!e.is_hit() && !g.is_hit()) {
        return Ok(true);
    }
    if e.is_hit() && g.is_hit() {
        let near = close(e.t, g.t);
        if e.prim == g.prim && near {
            return Ok(false);
        }
        if e.prim != g.prim && e.t.to_bits() == g.t.to_bits() {
            return Err(Class::TieEqualT);
        }
        if e.prim != g.prim && near {
            return Err(Class::NearTie);
        }
        if e.prim == g.prim {
            return Err(Class::SameTriangleFarT);
        }
    }
    if g.is_hit() && (!e.is_hit() || g.t < e.t) {
        Err(extra(ray, g, tris))
    } else {
        Err(missed(ray, e, tris))
    }
}

/// `Ok(true)` when both agree on occlusion, else why not.
fn any(ray: &Ray, e: &Hit, g: &Hit, tris: &[Triangle]) -> Result<bool, Class> {
    match (e.is_hit(), g.is_hit()) {
        (a, b) if a == b => Ok(true),
        (true, false) => Err(missed(ray, e, tris)),
        _ => Err(extra(ray, g, tris)),
    }
}

/// Why a target missed the reference's hit `e`.
fn missed(ray: &Ray, e: &Hit, tris: &[Triangle]) -> Class {
    let Some(tri) = tris.get(e.prim as usize) else { return Class::Other };
    if at_interval_end(ray, e.t) {
        Class::IntervalEnd
    } else if near_origin(ray, e.t, tri) {
        Class::NearOrigin
    } else if on_edge(ray, e.t, tri) {
        Class::MissOnEdge
    } else if back_facing(ray, tri) {
        Class::Backface
    } else if tiny_determinant(ray, tri) {
        Class::TinyDeterminant
    } else {
        Class::Other
    }
}

/// Why a target hit `g` where the reference hit nothing, or farther.
fn extra(ray: &Ray, g: &Hit, tris: &[Triangle]) -> Class {
    let Some(tri) = tris.get(g.prim as usize) else { return Class::Other };
    if at_interval_end(ray, g.t) {
        Class::IntervalEnd
    } else if on_edge(ray, g.t, tri) {
        Class::ExtraOnEdge
    } else {
        Class::Other
    }
}

/// Whether two distances agree within [`T_TOLERANCE`].
fn close(a: f32, b: f32) -> bool {
    let (a, b) = (f64::from(a), f64::from(b));
    (a - b).abs() <= T_TOLERANCE * a.abs().max(b.abs())
}

/// Whether `t` is at `tmin` or `tmax` within the tolerance.
fn at_interval_end(ray: &Ray, t: f32) -> bool {
    (ray.tmin > 0.0 && close(t, ray.tmin)) || (ray.tmax.is_finite() && close(t, ray.tmax))
}

/// Whether the point at `t` on the ray lies within [`EDGE`] (barycentric) of an edge of `tri`.
fn on_edge(ray: &Ray, t: f32, tri: &Triangle) -> bool {
    let p = ray.origin().as_dvec3() + ray.dir().as_dvec3() * f64::from(t);
    let [a, b, c] = tri.v.map(|v| v.as_dvec3());
    barycentrics(p, a, b, c).is_some_and(|w| w.min_element() < EDGE)
}

/// Barycentric weights of `p` projected onto the plane of `(a, b, c)`; `None` when degenerate.
fn barycentrics(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<DVec3> {
    let (e1, e2, q) = (b - a, c - a, p - a);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if det.abs() <= f64::MIN_POSITIVE {
        return None;
    }
    let (q1, q2) = (q.dot(e1), q.dot(e2));
    let v = (d22 * q1 - d12 * q2) / det;
    let w = (d11 * q2 - d12 * q1) / det;
    Some(DVec3::new(1.0 - v - w, v, w))
}

/// Whether the ray sees `tri` from its back (clockwise winding as seen along the ray).
fn back_facing(ray: &Ray, tri: &Triangle) -> bool {
    let [a, b, c] = tri.v.map(|v| v.as_dvec3());
    (b - a).cross(c - a).dot(ray.dir().as_dvec3()) > 0.0
}

/// Whether the point at `t` lies within 1e-3 of the largest coordinate magnitude (of the origin
/// and `tri`) from the ray's origin.
fn near_origin(ray: &Ray, t: f32, tri: &Triangle) -> bool {
    let scale = tri.v.iter().fold(ray.origin().abs().max_element(), |m, v| m.max(v.abs().max_element()));
    f64::from(t) * ray.dir().as_dvec3().length() <= 1e-3 * f64::from(scale)
}

/// Whether `|((b - a) x (c - a)) . d / |d||` is below `f32::EPSILON`.
fn tiny_determinant(ray: &Ray, tri: &Triangle) -> bool {
    let [a, b, c] = tri.v.map(|v| v.as_dvec3());
    let d = ray.dir().as_dvec3().normalize_or_zero();
    (b - a).cross(c - a).dot(d).abs() < f64::from(f32::EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn classes_of_closest_hits() {
        let tris = [
            Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y),
            Triangle::new(Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y),
            // A tiny triangle around (5, 5, 0): twice its area is 9e-8.
            Triangle::new(
                Vec3::new(4.9999, 4.9999, 0.0),
                Vec3::new(5.0002, 4.9999, 0.0),
                Vec3::new(4.9999, 5.0002, 0.0),
            ),
        ];
        // Down onto the middle of triangle 0, and down onto the shared edge x + y = 1.
        let rays = [
            Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z, 0.0, f32::INFINITY),
            Ray::new(Vec3::new(0.5, 0.5, 1.0), Vec3::NEG_Z, 0.0, f32::INFINITY),
            Ray::new(Vec3::new(0.2, 0.2, -1.0), Vec3::Z, 0.0, f32::INFINITY),
            Ray::new(Vec3::new(5.0, 5.0, 1.0), Vec3::NEG_Z, 0.0, f32::INFINITY),
        ];
        let hit = |prim, t: f32| Hit { t, prim, u: 0.0, v: 0.0 };
        let t_just_off = f32::from_bits(1.0f32.to_bits() + 1);
        let cases = [
            (rays[0], hit(0, 1.0), hit(0, 1.0), Ok(true)),
            (rays[0], hit(0, 1.0), hit(0, t_just_off), Ok(false)),
            (rays[1], hit(0, 1.0), hit(1, 1.0), Err(Class::TieEqualT)),
            (rays[1], hit(0, 1.0), hit(1, t_just_off), Err(Class::NearTie)),
            (rays[0], hit(0, 1.0), hit(0, 1.001), Err(Class::SameTriangleFarT)),
            (rays[1], hit(0, 1.0), Hit::MISS, Err(Class::MissOnEdge)),
            (rays[1], Hit::MISS, hit(1, 1.0), Err(Class::ExtraOnEdge)),
            (rays[0], hit(0, 1.0), Hit::MISS, Err(Class::Other)),
            // From below, triangle 0 (counter-clockwise from above) shows its back.
            (rays[2], hit(0, 1.0), Hit::MISS, Err(Class::Backface)),
            (rays[3], hit(2, 1.0), Hit::MISS, Err(Class::TinyDeterminant)),
            (rays[0], hit(0, 1e-4), Hit::MISS, Err(Class::NearOrigin)),
        ];
        for (i, (ray, e, g, want)) in cases.into_iter().enumerate() {
            assert_eq!(closest(&ray, &e, &g, &tris), want, "case {i}");
        }
        let a = compare(Query::Closest, &rays[..2], &[hit(0, 1.0); 2], &[hit(0, 1.0), hit(1, 1.0)], &tris);
        assert_eq!((a.rays, a.exact, a.close), (2, 1, 1));
        assert_eq!(a.classes.get(&Class::TieEqualT), Some(&1));
    }

    #[test]
    fn any_hit_compares_occlusion_and_interval_ends() {
        let tris = [Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
        let ray = Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z, 0.5, 1.0);
        let at_end = Hit { t: 1.0, prim: 0, u: 0.2, v: 0.2 };
        let elsewhere = Hit { t: 0.9, prim: 0, u: 0.2, v: 0.2 };
        assert_eq!(any(&ray, &at_end, &elsewhere, &tris), Ok(true));
        assert_eq!(any(&ray, &at_end, &Hit::MISS, &tris), Err(Class::IntervalEnd));
        assert_eq!(any(&ray, &Hit::MISS, &elsewhere, &tris), Err(Class::Other));
    }
}
