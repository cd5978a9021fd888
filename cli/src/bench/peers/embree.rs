//! Embree 3 (Intel's ray-tracing kernels; the system's `libembree3`, 3.13.5 on Debian), through
//! the `embree3` crate's bindings, behind the `embree` cargo feature.
//!
//! The scene is one triangle geometry holding the scene's triangles in file order, each with its
//! own three vertices (no sharing), so Embree's primitive id is raytrail's. It is built with no
//! scene flags (not `ROBUST`), on a device with as many build threads as the bench's largest
//! pool, at one of two build qualities, each a peer of its own: `embree`, Embree's default
//! (medium), and `embree-high` (`RTC_BUILD_QUALITY_HIGH`, spatial splits: what a renderer picks
//! for a static scene, slower to build and faster to trace). The build time is that of
//! `rtcCommitScene`; the memory is what Embree's memory monitor reports while the buffers are
//! made and while the scene is committed.
//!
//! Tracing is one ray at a time (`rtcIntersect1`, `rtcOccluded1`) with a default intersection
//! context, in the same chunks on the same rayon pool as the other peers. Closest hits come with
//! `t`, primitive id and Embree's `u`, `v` (the weights of the second and third vertex, as
//! raytrail's). An occlusion query reports only whether something was hit, so an any hit has
//! an unknown primitive ([`UNKNOWN_PRIM`]) and `t` (NaN); the agreement compares occlusion only.
//!
//! Embree's own hit rule, as seen on test rays: a hit at `t = tmax` counts, one at `t = tmin`
//! does not. Embree has no callback-free way to count triangle tests, so its work is not
//! reported, and there is no `+wt` variant (raytrail's test would need a user geometry).

use super::par_trace;
use crate::bench::report::Built;
use crate::bench::target::{BenchTarget, TargetKind, Work};
use embree3::{BuildQuality, Config, Device, IntersectContext, Ray as EmbreeRay, RayHit, Scene as EmbreeScene};
use raytrail::core::method::Query;
use raytrail::core::scene::Scene;
use raytrail::core::{Hit, Ray};
use std::sync::atomic::{AtomicIsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Primitive id of an any hit, which Embree's occlusion query does not report.
pub const UNKNOWN_PRIM: u32 = Hit::REFUSED_PRIM - 1;

/// Embree's build quality, a peer each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    /// The default, `RTC_BUILD_QUALITY_MEDIUM`: the peer `embree`.
    Medium,
    /// `RTC_BUILD_QUALITY_HIGH` (spatial splits): the peer `embree-high`.
    High,
}

impl Quality {
    /// Both, as the bench names them.
    pub const ALL: [Quality; 2] = [Quality::Medium, Quality::High];

    /// The peer's name.
    pub fn name(self) -> &'static str {
        match self {
            Quality::Medium => "embree",
            Quality::High => "embree-high",
        }
    }

    /// The quality of a peer name.
    pub fn from_name(name: &str) -> Option<Quality> {
        Self::ALL.into_iter().find(|q| q.name() == name)
    }

    fn embree(self) -> BuildQuality {
        match self {
            Quality::Medium => BuildQuality::MEDIUM,
            Quality::High => BuildQuality::HIGH,
        }
    }
}

/// Why Embree could not build a scene: the step that failed and Embree's error code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EmbreeError {
    /// The step: "cannot create a device", "the build failed", ...
    pub step: &'static str,
    /// Embree's error code.
    pub code: embree3::Error,
}

impl std::fmt::Display for EmbreeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "embree: {}: {:?}", self.step, self.code)
    }
}

impl std::error::Error for EmbreeError {}

/// An Embree scene over a raytrail scene: a bench target.
pub struct Embree {
    scene: EmbreeScene<'static>,
    quality: Quality,
}

impl Embree {
    /// Builds the Embree scene over `scene` at `quality` with `threads` build threads; returns it
    /// and what the build cost.
    pub fn new(scene: &Scene, threads: usize, quality: Quality) -> Result<(Self, Built), EmbreeError> {
        let fail = |step: &'static str, code: embree3::Error| EmbreeError { step, code };
        let config = Config { threads: u32::try_from(threads).unwrap_or(0), ..Config::default() };
        let device = Device::with_config(config).map_err(|e| fail("cannot create a device", e))?;
        let allocated = Arc::new(AtomicIsize::new(0));
        let counter = allocated.clone();
        device.set_memory_monitor_function(move |bytes, _| {
            counter.fetch_add(bytes, Ordering::Relaxed);
            true
        });
        let geometry =
            raytrail_cli::embree_mesh::triangle_geometry(&device, scene).map_err(|(step, e)| fail(step, e))?;
        let buffer_bytes = allocated.load(Ordering::Relaxed);
        let geometry = geometry.commit();
        let mut embree = device.create_scene().map_err(|e| fail("cannot create a scene", e))?;
        embree.set_build_quality(quality.embree());
        embree.attach_geometry(&geometry);
        let before_commit = allocated.load(Ordering::Relaxed);
        let start = Instant::now();
        embree.commit();
        let seconds = start.elapsed().as_secs_f64();
        let bvh_bytes = allocated.load(Ordering::Relaxed) - before_commit;
        device.unset_memory_monitor_function();
        let error = device.get_error();
        if error != embree3::Error::NONE {
            return Err(fail("the build failed", error));
        }
        let bytes = [("vertex and index buffers", buffer_bytes), ("BVH (memory monitor)", bvh_bytes)]
            .into_iter()
            .map(|(what, n)| (what.to_string(), usize::try_from(n).unwrap_or(0)))
            .collect();
        let what = match quality {
            Quality::Medium => "embree (default quality, rtcCommitScene)",
            Quality::High => "embree-high (RTC_BUILD_QUALITY_HIGH, rtcCommitScene)",
        };
        Ok((Self { scene: embree, quality }, Built { what: what.to_string(), seconds, bytes }))
    }

    /// Closest hit of one ray (`rtcIntersect1`).
    #[inline(always)]
    fn closest(&self, r: &Ray) -> Hit {
        let mut rh = RayHit::from(EmbreeRay::segment(r.origin, r.dir, r.tmin, r.tmax));
        self.scene.intersect(&mut IntersectContext::incoherent(), &mut rh);
        if rh.hit.is_valid() {
            Hit { t: rh.ray.tfar, prim: rh.hit.primID, u: rh.hit.u, v: rh.hit.v }
        } else {
            Hit::MISS
        }
    }

    /// Whether one ray hits anything (`rtcOccluded1`).
    #[inline(always)]
    fn any(&self, r: &Ray) -> Hit {
        let mut ray = EmbreeRay::segment(r.origin, r.dir, r.tmin, r.tmax);
        if self.scene.occluded(&mut IntersectContext::incoherent(), &mut ray) {
            Hit { t: f32::NAN, prim: UNKNOWN_PRIM, u: 0.0, v: 0.0 }
        } else {
            Hit::MISS
        }
    }
}

impl BenchTarget for Embree {
    fn name(&self) -> &str {
        self.quality.name()
    }

    fn kind(&self) -> TargetKind {
        TargetKind::PeerOwnTest
    }

    fn trace(&self, pool: &rayon::ThreadPool, rays: &[Ray], query: Query, hits: &mut [Hit]) -> Result<(), String> {
        match query {
            Query::Closest => par_trace(pool, rays, hits, |r| (self.closest(r), 0)),
            Query::Any => par_trace(pool, rays, hits, |r| (self.any(r), 0)),
        }
        .map(|_| ())
    }

    fn work(&self, _: &rayon::ThreadPool, _: &[Ray], _: Query) -> Result<Option<Work>, String> {
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::args::builtin_scene;
    use crate::bench::agreement::compare;
    use raytrail::core::method::{Bvh2Method, Method};
    use raytrail::core::prepared::PreparedScene;
    use raytrail::core::trace::{Trace, TraceOptions};
    use raytrail::cpu::{CpuBackend, CpuScene};
    use raytrail::Builder;
    use raytrail_conformance::rays::{primary, shadow};

    /// The stack method's hits on `rays`.
    fn stack_hits(scene: &Scene, rays: &[Ray], query: Query) -> Vec<Hit> {
        let bvh = Builder::Sah.build(scene).unwrap();
        let method = Method::Bvh2(Bvh2Method::Stack);
        let prepared = PreparedScene::new(scene, bvh, &[method]).unwrap();
        let mut hits = vec![Hit::MISS; rays.len()];
        let opts = TraceOptions::new(method).query(query);
        CpuBackend::new().trace(&CpuScene(Arc::new(prepared)), rays, &opts, &mut hits).unwrap();
        hits
    }

    #[test]
    fn embree_agrees_with_the_stack_method_at_both_qualities() {
        for quality in Quality::ALL {
            agrees_with_the_stack_method(quality);
        }
        assert_eq!(Quality::from_name("embree-high"), Some(Quality::High));
        assert_eq!(Quality::from_name("embree-low"), None);
    }

    fn agrees_with_the_stack_method(quality: Quality) {
        let named = builtin_scene();
        let scene = &named.scene;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let (embree, built) = Embree::new(scene, 2, quality).unwrap();
        assert!(built.seconds >= 0.0);
        assert!(built.bytes.iter().all(|(_, n)| *n > 0), "{:?}", built.bytes);
        assert_eq!(embree.name(), quality.name());
        assert!(built.what.starts_with(quality.name()));

        let rays = primary(scene, 64, 48);
        let expected = stack_hits(scene, &rays, Query::Closest);
        let mut got = vec![Hit::MISS; rays.len()];
        embree.trace(&pool, &rays, Query::Closest, &mut got).unwrap();
        let hits = expected.iter().filter(|h| h.is_hit()).count();
        assert!(hits > rays.len() / 10, "the camera sees the scene: {hits} hits");
        // Same primitive and t within the bench's tolerance on nearly every ray; the rest are
        // hits on shared edges or near-ties, which a different triangle test may resolve apart.
        let a = compare(Query::Closest, &rays, &expected, &got, scene.triangles());
        assert!(a.close_pct() >= 99.5, "{:.3}% within tolerance: {:?}", a.close_pct(), a.classes);
        for (g, e) in got.iter().zip(&expected) {
            if g.is_hit() && g.prim == e.prim {
                assert!((g.u - e.u).abs() < 1e-3 && (g.v - e.v).abs() < 1e-3, "{g:?} vs {e:?}");
            }
        }

        let bounds = scene.bounds();
        let light = bounds.center() + glam::Vec3::new(0.0, 2.0, 0.5) * bounds.extent().length();
        let shadows = shadow(&rays, &expected, light, raytrail_conformance::rays::scene_epsilon(bounds));
        let expected = stack_hits(scene, &shadows, Query::Any);
        let mut got = vec![Hit::MISS; shadows.len()];
        embree.trace(&pool, &shadows, Query::Any, &mut got).unwrap();
        let a = compare(Query::Any, &shadows, &expected, &got, scene.triangles());
        assert!(a.exact_pct() >= 99.5, "{:.3}% same occlusion: {:?}", a.exact_pct(), a.classes);
        assert!(got.iter().any(|h| h.is_hit()) && got.iter().any(|h| !h.is_hit()));
        assert!(got.iter().filter(|h| h.is_hit()).all(|h| h.prim == UNKNOWN_PRIM));
    }
}
