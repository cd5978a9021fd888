//! The bench's ray types, made once per scene: primary, shadow, soft shadow, diffuse and ambient
//! occlusion.
//!
//! Primary, shadow and diffuse rays come from the conformance suite's generators; the soft-shadow
//! and ambient-occlusion generators live here. Primary rays come from one camera [`View`] of the
//! scene; the other kinds follow from their hits, so each view gets its own four sets.

use super::view::View;
use glam::Vec3;
use raytrail::core::method::Query;
use raytrail::core::scene::Scene;
use raytrail::core::{Hit, Ray};
use raytrail_conformance::rays::{default_light, diffuse, primary_from, scene_epsilon, shadow, RAY_SEED};
use raytrail_conformance::rng::Pcg32;

/// Length of an ambient-occlusion ray, as a fraction of the scene's diagonal.
pub const AO_RADIUS: f32 = 0.05;

/// Seed stream of the ambient-occlusion rays (distinct from the diffuse rays' [`RAY_SEED`]).
const AO_SEED: u64 = RAY_SEED ^ 0xA0;

/// Seed stream of the soft-shadow rays.
const SOFT_SHADOW_SEED: u64 = RAY_SEED ^ 0x50F7;

/// Soft-shadow rays per primary hit: a 2 x 2 stratification of the area light (Garanzha & Loop
/// use up to 16 per shading point; 4 keeps the batch the size of the others).
pub const SOFT_SHADOW_SAMPLES: usize = 4;

/// Side of the square area light, as a fraction of the scene's diagonal.
pub const AREA_LIGHT_SIDE: f32 = 0.25;

/// A kind of ray the bench traces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RayKind {
    /// Camera rays in Morton order, closest hit.
    Primary,
    /// From primary hits to a point light, any hit.
    Shadow,
    /// From primary hits to stratified points of a square area light, any hit: the coherent
    /// secondary rays of Garanzha & Loop's measurements.
    SoftShadow,
    /// Cosine-weighted bounces from primary hits, closest hit.
    Diffuse,
    /// Short cosine-weighted rays from primary hits, any hit.
    Ao,
}

impl RayKind {
    /// Every kind, in the order they are made and reported.
    pub const ALL: [RayKind; 5] =
        [RayKind::Primary, RayKind::Shadow, RayKind::SoftShadow, RayKind::Diffuse, RayKind::Ao];

    /// Command-line and report name.
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Primary => "primary",
            RayKind::Shadow => "shadow",
            RayKind::SoftShadow => "soft-shadow",
            RayKind::Diffuse => "diffuse",
            RayKind::Ao => "ao",
        }
    }

    /// The kind of a command-line name.
    pub fn from_name(name: &str) -> Option<RayKind> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Closest hit or any hit.
    pub fn query(self) -> Query {
        match self {
            RayKind::Primary | RayKind::Diffuse => Query::Closest,
            RayKind::Shadow | RayKind::SoftShadow | RayKind::Ao => Query::Any,
        }
    }
}

/// One batch of rays of one kind.
#[derive(Clone, Debug)]
pub struct RayBatch {
    /// What the rays are.
    pub kind: RayKind,
    /// The rays.
    pub rays: Vec<Ray>,
}

/// The requested batches, in the order of `kinds`, from the primary rays and their closest hits
/// (`primary_hits`, traced by the caller with a reference method).
pub fn batches(
    kinds: &[RayKind],
    scene: &Scene,
    primary_rays: &[Ray],
    primary_hits: &[Hit],
    ao_per_hit: usize,
) -> Vec<RayBatch> {
    let bounds = scene.bounds();
    kinds
        .iter()
        .map(|&kind| {
            let rays = match kind {
                RayKind::Primary => primary_rays.to_vec(),
                RayKind::Shadow => shadow(primary_rays, primary_hits, default_light(bounds), scene_epsilon(bounds)),
                RayKind::SoftShadow => soft_shadow(primary_rays, primary_hits, scene, SOFT_SHADOW_SEED),
                RayKind::Diffuse => diffuse(primary_rays, primary_hits, scene, RAY_SEED),
                RayKind::Ao => ambient_occlusion(primary_rays, primary_hits, scene, ao_per_hit, AO_SEED),
            };
            RayBatch { kind, rays }
        })
        .collect()
}

/// Primary rays of `view` of `scene` (Morton order), as the conformance suite makes them; from
/// outside, the conformance suite's own primary rays.
pub fn primary_rays(scene: &Scene, view: View, width: u32, height: u32) -> Vec<Ray> {
    primary_from(&view.camera(scene.bounds()), width, height)
}

/// The order a run's rays come in. The secondary rays are made from the primary hits in the
/// primary rays' order, so the stream and packet walks, which gain from neighbours that go the
/// same way, see that coherence unless the rays are shuffled: a path tracer's later bounces
/// come in no useful order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayOrder {
    /// Camera rays along a Z-curve over the image, secondary rays following them.
    Morton,
    /// Camera rays row by row, secondary rays following them (their random directions are drawn
    /// per primary ray by its place in this order, so they are other draws than Morton's).
    Raster,
    /// Camera rays as for Morton; every secondary batch shuffled by a fixed seed.
    Shuffled,
}

impl RayOrder {
    /// Every order, the default first.
    pub const ALL: [RayOrder; 3] = [RayOrder::Morton, RayOrder::Raster, RayOrder::Shuffled];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            RayOrder::Morton => "morton",
            RayOrder::Raster => "raster",
            RayOrder::Shuffled => "shuffled",
        }
    }

    /// The order of a command-line name.
    pub fn from_name(name: &str) -> Option<RayOrder> {
        Self::ALL.into_iter().find(|o| o.name() == name)
    }

    /// Primary rays of `view` of `scene` in this order.
    pub fn primary_rays(self, scene: &Scene, view: View, width: u32, height: u32) -> Vec<Ray> {
        match self {
            RayOrder::Morton | RayOrder::Shuffled => primary_rays(scene, view, width, height),
            RayOrder::Raster => {
                let camera = view.camera(scene.bounds());
                (0..height)
                    .flat_map(|y| (0..width).map(move |x| (x, y)))
                    .map(|(x, y)| camera.ray(x as f32 + 0.5, y as f32 + 0.5, width, height))
                    .collect()
            }
        }
    }

    /// Puts the secondary batches of `batches` in this order (the shuffle's seed is fixed per
    /// ray kind, so every run and every target sees the same sequence).
    pub fn arrange(self, batches: &mut [RayBatch]) {
        if self != RayOrder::Shuffled {
            return;
        }
        for b in batches.iter_mut().filter(|b| b.kind != RayKind::Primary) {
            Pcg32::new(ORDER_SEED, b.kind as u64).shuffle(&mut b.rays);
        }
    }
}

/// Seed stream of the shuffled order.
const ORDER_SEED: u64 = RAY_SEED ^ 0x5EED;

/// `per_hit` ambient-occlusion rays per hit of `rays` (misses, non-finite hits and zero-area
/// triangles skipped), grouped by primary ray in the order of `rays`.
///
/// Each ray leaves the hit point, pushed off the surface along the geometric normal (turned to face
/// the incoming ray) by [`scene_epsilon`], in a cosine-weighted direction around that normal
/// (unit length), over `t` in `[0, AO_RADIUS * diagonal]`. The random stream of each primary ray
/// is keyed by its index, so its rays do not change when other rays start hitting or missing.
pub fn ambient_occlusion(rays: &[Ray], hits: &[Hit], scene: &Scene, per_hit: usize, seed: u64) -> Vec<Ray> {
    let shape = AoShape::of(scene, AO_RADIUS, per_hit);
    let mut out = Vec::with_capacity(hits.iter().filter(|h| h.is_hit()).count() * per_hit);
    for (i, (ray, hit)) in rays.iter().zip(hits).enumerate() {
        shape.push_rays(scene, ray, hit, &mut Pcg32::new(seed, i as u64), &mut out);
    }
    out
}

/// [`SOFT_SHADOW_SAMPLES`] rays per hit of `rays` toward a square area light, grouped by primary
/// ray in the order of `rays`.
///
/// The light is centred on the point light of the shadow rays ([`default_light`]), faces the
/// scene's centre, and has a side of [`AREA_LIGHT_SIDE`] of the diagonal. Sample `k` of a hit falls
/// in stratum `k` of a 2 x 2 grid over the light, jittered; the ray runs from the hit point to the
/// sample over `[eps / len, 1 - eps / len]` as the point-light shadow rays do. Each primary ray's
/// random stream is keyed by its index.
pub fn soft_shadow(rays: &[Ray], hits: &[Hit], scene: &Scene, seed: u64) -> Vec<Ray> {
    let bounds = scene.bounds();
    let (center, eps) = (default_light(bounds), scene_epsilon(bounds));
    let side = AREA_LIGHT_SIDE * bounds.extent().length().max(f32::MIN_POSITIVE);
    let (u, v) = (center - bounds.center()).normalize_or(Vec3::Y).any_orthonormal_pair();
    let strata = (SOFT_SHADOW_SAMPLES as f32).sqrt().ceil() as usize;
    let mut out = Vec::with_capacity(hits.iter().filter(|h| h.is_hit()).count() * SOFT_SHADOW_SAMPLES);
    for (i, (ray, hit)) in rays.iter().zip(hits).enumerate() {
        let Some(p) = hit_point(ray, hit) else { continue };
        let mut rng = Pcg32::new(seed, i as u64);
        for k in 0..SOFT_SHADOW_SAMPLES {
            let sx = ((k % strata) as f32 + rng.next_f32()) / strata as f32 - 0.5;
            let sy = ((k / strata) as f32 + rng.next_f32()) / strata as f32 - 0.5;
            let dir = center + (u * sx + v * sy) * side - p;
            let len = dir.length();
            if len.is_finite() && len > 2.0 * eps {
                out.push(Ray::new(p, dir, eps / len, 1.0 - eps / len));
            }
        }
    }
    out
}

/// How ambient-occlusion rays are made from a hit: how far they go, how far off the surface they
/// start, how many per hit.
#[derive(Clone, Copy, Debug)]
pub struct AoShape {
    /// Ray length.
    pub radius: f32,
    /// Offset of the origin along the normal ([`scene_epsilon`]).
    pub eps: f32,
    /// Rays per hit.
    pub per_hit: usize,
}

impl AoShape {
    /// Rays of `radius_fraction` of `scene`'s diagonal (at least four epsilons), `per_hit` a hit.
    pub fn of(scene: &Scene, radius_fraction: f32, per_hit: usize) -> AoShape {
        let bounds = scene.bounds();
        let eps = scene_epsilon(bounds);
        AoShape { radius: (radius_fraction * bounds.extent().length()).max(eps * 4.0), eps, per_hit }
    }

    /// Pushes the rays of one closest hit onto `out` (see [`ambient_occlusion`]); returns whether
    /// it pushed any (not for a miss, a non-finite hit or a zero-area triangle).
    pub fn push_rays(&self, scene: &Scene, ray: &Ray, hit: &Hit, rng: &mut Pcg32, out: &mut Vec<Ray>) -> bool {
        let (Some(p), Some(n)) = (hit_point(ray, hit), facing_normal(scene, ray, hit)) else { return false };
        for _ in 0..self.per_hit {
            out.push(Ray::new(p + n * self.eps, cosine_direction(n, rng.in_unit_disk()), 0.0, self.radius));
        }
        true
    }
}

/// The geometric normal of the hit triangle, turned to face the ray; `None` for a miss or a
/// zero-area triangle.
pub fn facing_normal(scene: &Scene, ray: &Ray, hit: &Hit) -> Option<Vec3> {
    if !hit.is_hit() {
        return None;
    }
    let t = scene.triangles().get(hit.prim as usize)?;
    let n = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]).normalize_or_zero();
    if n == Vec3::ZERO {
        return None;
    }
    Some(if n.dot(ray.dir()) > 0.0 { -n } else { n })
}

/// The hit point of a closest hit (evaluated in `f64`, rounded once), or `None` for a miss or a
/// non-finite point.
fn hit_point(ray: &Ray, hit: &Hit) -> Option<Vec3> {
    if !hit.is_hit() || !hit.t.is_finite() {
        return None;
    }
    let p = (ray.origin().as_dvec3() + ray.dir().as_dvec3() * f64::from(hit.t)).as_vec3();
    p.is_finite().then_some(p)
}

/// A unit direction around the unit normal `n` with density proportional to the cosine, from a
/// uniform point `(x, y)` of the unit disk lifted onto the hemisphere (Malley's method).
fn cosine_direction(n: Vec3, (x, y): (f32, f32)) -> Vec3 {
    let (t, b) = n.any_orthonormal_pair();
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    (t * x + b * y + n * z).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail::core::geometry::Triangle;

    /// A unit square at z = 0 made of two triangles, seen from above.
    fn floor() -> Scene {
        let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
        Scene::new(vec![Triangle::new(a, b, c), Triangle::new(a, c, d)]).unwrap()
    }

    #[test]
    fn the_orders_hold_the_same_camera_pixels_and_shuffle_only_secondary_rays() {
        let scene = floor();
        let key = |r: &Ray| (r.origin.map(f32::to_bits), r.dir.map(f32::to_bits));
        let morton = RayOrder::Morton.primary_rays(&scene, View::Outside, 8, 6);
        let mut raster = RayOrder::Raster.primary_rays(&scene, View::Outside, 8, 6);
        assert_ne!(morton, raster);
        let mut sorted = morton.clone();
        sorted.sort_by_key(key);
        raster.sort_by_key(key);
        assert_eq!(sorted, raster, "raster and Morton order hold the same camera rays");
        let hits = vec![Hit { t: 1.0, prim: 0, u: 0.2, v: 0.2 }; morton.len()];
        let mut batches = batches(&[RayKind::Primary, RayKind::Ao], &scene, &morton, &hits, 2);
        let before = batches.clone();
        RayOrder::Shuffled.arrange(&mut batches);
        assert_eq!(batches[0].rays, before[0].rays, "camera rays keep their order");
        assert_ne!(batches[1].rays, before[1].rays);
        let (mut a, mut b) = (batches[1].rays.clone(), before[1].rays.clone());
        a.sort_by_key(key);
        b.sort_by_key(key);
        assert_eq!(a, b, "shuffling keeps the rays");
    }

    #[test]
    fn ao_rays_leave_the_surface_into_the_hemisphere() {
        let scene = floor();
        let rays: Vec<Ray> = (0..50)
            .map(|i| Ray::new(Vec3::new(0.01 + i as f32 * 0.019, 0.3, 2.0), Vec3::NEG_Z, 0.0, f32::INFINITY))
            .collect();
        let mut hits: Vec<Hit> = rays.iter().map(|_| Hit { t: 2.0, prim: 0, u: 0.1, v: 0.1 }).collect();
        hits[7] = Hit::MISS;
        let ao = ambient_occlusion(&rays, &hits, &scene, 4, 1);
        assert_eq!(ao.len(), 49 * 4);
        let diagonal = scene.bounds().extent().length();
        let mut mean_cos = 0.0;
        for r in &ao {
            let d = r.dir();
            assert!((d.length() - 1.0).abs() < 1e-5);
            // The triangle's normal is +z (counter-clockwise from above) and faces the ray already.
            assert!(d.z >= 0.0, "{d}");
            assert!(r.origin[2] > 0.0 && r.tmin == 0.0);
            assert!((r.tmax - AO_RADIUS * diagonal).abs() < 1e-6);
            mean_cos += d.z / ao.len() as f32;
        }
        // Cosine-weighted: E[cos] = 2/3 (uniform would give 1/2).
        assert!((mean_cos - 2.0 / 3.0).abs() < 0.05, "{mean_cos}");
        // Seen from below, the normal flips.
        let below = [Ray::new(Vec3::new(0.5, 0.3, -2.0), Vec3::Z, 0.0, f32::INFINITY)];
        let ao = ambient_occlusion(&below, &[Hit { t: 2.0, prim: 1, u: 0.2, v: 0.2 }], &scene, 8, 1);
        assert!(ao.iter().all(|r| r.dir[2] <= 0.0 && r.origin[2] < 0.0));
    }

    #[test]
    fn the_outside_view_is_the_conformance_framing() {
        let scene = floor();
        assert_eq!(primary_rays(&scene, View::Outside, 8, 6), raytrail_conformance::rays::primary(&scene, 8, 6));
        let inside = primary_rays(&scene, View::Inside, 8, 6);
        assert_eq!(inside.len(), 48);
        let eye = View::Inside.camera(scene.bounds()).eye;
        assert!(inside.iter().all(|r| r.origin() == eye));
    }

    #[test]
    fn kinds_round_trip_and_query() {
        for k in RayKind::ALL {
            assert_eq!(RayKind::from_name(k.name()), Some(k));
        }
        assert_eq!(RayKind::Ao.query(), Query::Any);
        assert_eq!(RayKind::Diffuse.query(), Query::Closest);
    }
}
