//! Ray sets: deterministic batches of rays for a scene, each stressing traversal differently.
//!
//! - [`primary`]: coherent camera rays in Morton order.
//! - [`shadow`]: any-hit rays from the primary hits to a point light.
//! - [`diffuse`]: incoherent bounce rays from the primary hits.
//! - [`uniform_random`]: rays from anywhere in any direction.
//! - [`adversarial`]: signed zeros, rays through vertices and edges, origins on box planes,
//!   NaN/inf, odd intervals and extreme magnitudes.
//!
//! [`ray_sets`] makes all five for a scene; shadow and diffuse rays need the primary rays' closest
//! hits, which the caller supplies by tracing.

mod adversarial;
mod diffuse;
mod inside;
mod points;
mod primary;
mod shadow;
mod uniform;

pub use adversarial::adversarial;
pub use diffuse::diffuse;
pub use inside::up_axis;
pub use points::query_points;
pub use primary::{morton_encode, morton_order, primary, primary_from, Camera};
pub use shadow::shadow;
pub use uniform::uniform_random;

use core::fmt;
use glam::Vec3;
use raytrail_core::scene::Scene;
use raytrail_core::{Aabb, Hit, Ray};

/// Seed of the random ray sets made by [`ray_sets`]; fixed so the suite is the same on every run.
pub const RAY_SEED: u64 = 0x7a11;

/// The kinds of ray set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum RaySetKind {
    /// Camera rays in Morton order ([`primary`]).
    Primary,
    /// Rays from primary hits to a light, an any-hit query ([`shadow`]).
    Shadow,
    /// Cosine-weighted bounces from primary hits ([`diffuse`]).
    Diffuse,
    /// Uniform origins and directions ([`uniform_random`]).
    Uniform,
    /// Edge cases ([`adversarial`]).
    Adversarial,
}

impl RaySetKind {
    /// Every kind, in the order [`ray_sets`] returns them.
    pub const ALL: [RaySetKind; 5] =
        [RaySetKind::Primary, RaySetKind::Shadow, RaySetKind::Diffuse, RaySetKind::Uniform, RaySetKind::Adversarial];

    /// Short lowercase name, as reported.
    pub fn name(self) -> &'static str {
        match self {
            RaySetKind::Primary => "primary",
            RaySetKind::Shadow => "shadow",
            RaySetKind::Diffuse => "diffuse",
            RaySetKind::Uniform => "uniform",
            RaySetKind::Adversarial => "adversarial",
        }
    }

    /// Whether the set is meant as an any-hit (occlusion) query; the others are closest-hit.
    pub fn is_any_hit(self) -> bool {
        self == RaySetKind::Shadow
    }
}

impl fmt::Display for RaySetKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A batch of rays of one kind.
#[derive(Clone, Debug, PartialEq)]
pub struct RaySet {
    /// What the rays are.
    pub kind: RaySetKind,
    /// The rays.
    pub rays: Vec<Ray>,
}

/// How many rays [`ray_sets`] makes: the primary image size (shadow and diffuse rays follow from
/// its hits) and the number of uniform rays. Adversarial sets have a fixed size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RaySetSize {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Number of uniform random rays.
    pub uniform_count: usize,
}

impl RaySetSize {
    /// Small sets for unit tests: 64 x 48 primary rays, 4,096 uniform.
    pub const SMALL: RaySetSize = RaySetSize { width: 64, height: 48, uniform_count: 4096 };
    /// The conformance suite's sets: 256 x 192 primary rays, 65,536 uniform.
    pub const SUITE: RaySetSize = RaySetSize { width: 256, height: 192, uniform_count: 65_536 };
}

/// All five ray sets for `scene`, in the order of [`RaySetKind::ALL`], from the fixed [`RAY_SEED`].
///
/// `trace_closest` must return the closest hit of each ray it is given, in order (the caller's
/// reference tracer); it is called once, on the primary rays. The light of the shadow rays is
/// [`default_light`]. Panics if `trace_closest` returns a different number of hits.
pub fn ray_sets(scene: &Scene, size: RaySetSize, trace_closest: &mut dyn FnMut(&[Ray]) -> Vec<Hit>) -> Vec<RaySet> {
    let bounds = scene.bounds();
    let primary_rays = primary(scene, size.width, size.height);
    let hits = trace_closest(&primary_rays);
    assert_eq!(hits.len(), primary_rays.len(), "ray_sets: trace_closest must return one hit per ray");
    let shadow_rays = shadow(&primary_rays, &hits, default_light(bounds), scene_epsilon(bounds));
    let diffuse_rays = diffuse(&primary_rays, &hits, scene, RAY_SEED);
    let sets = [
        primary_rays,
        shadow_rays,
        diffuse_rays,
        uniform_random(scene, size.uniform_count, RAY_SEED),
        adversarial(scene, RAY_SEED),
    ];
    RaySetKind::ALL.into_iter().zip(sets).map(|(kind, rays)| RaySet { kind, rays }).collect()
}

/// The offset that keeps secondary rays off the surface they leave: 1e-5 of the scene's diagonal,
/// but at least 2^-20 (about 8 ulps) of its largest coordinate magnitude, so it stays above
/// rounding for geometry far from the origin.
pub fn scene_epsilon(bounds: Aabb) -> f32 {
    let diagonal = bounds.extent().length();
    let magnitude = bounds.max_abs();
    (1e-5 * diagonal).max(magnitude * (1.0 / (1u32 << 20) as f32)).max(f32::MIN_POSITIVE)
}

/// A point light above and beside the scene, one diagonal from its center (outside its bounding
/// sphere), from a direction other than [`Camera::framing`]'s so shadows are visible.
pub fn default_light(bounds: Aabb) -> Vec3 {
    let diagonal = match bounds.extent().length() {
        d if d > 0.0 => d,
        _ => 1.0,
    };
    bounds.center() + Vec3::new(-0.3, 1.0, 0.45).normalize() * diagonal
}

/// The hit point of a closest hit, or `None` for a miss or a non-finite point; evaluated in `f64`
/// and rounded once, so it is as close to the true point on the ray as `f32` allows.
fn hit_point(ray: &Ray, hit: &Hit) -> Option<Vec3> {
    if !hit.is_hit() || !hit.t.is_finite() {
        return None;
    }
    let p = (ray.origin().as_dvec3() + ray.dir().as_dvec3() * f64::from(hit.t)).as_vec3();
    p.is_finite().then_some(p)
}

#[cfg(test)]
mod tests;
