//! [`InstancedTracer`]: meshes placed many times by affine transforms, traced in one call.
//!
//! Each mesh gets its own tree, built once however many times it is placed; a top-level BVH over
//! the placements' world boxes decides which instances a ray enters, and the ray is mapped into
//! each one's frame ([`raytrail_core::instance`] tells how, and why the answers agree with the
//! flattened triangles within the conformance suite's edge tolerance rather than bit for bit).

use crate::tracer::TracerBuilder;
use crate::Error;
use rayon::prelude::*;
use raytrail_core::instance::{trace_instanced, Instance, InstanceHit, InstancedReport, InstancedScene};
use raytrail_core::method::{Method, Query, WideMethod};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::scene::Scene;
use raytrail_core::trace::TraceOptions;
use raytrail_core::Ray;
use raytrail_cpu::{CpuBackend, CpuScene};
use std::sync::Arc;

/// The method an instanced tracer uses unless one is named: the single-ray walk of the 8-wide
/// tree of least node area, which suits the small per-instance batches instancing makes.
pub const INSTANCED_DEFAULT: Method = Method::Wide(WideMethod::BVH8_SAH);

/// Instances of triangle meshes, ready to trace on the CPU: closest hits
/// ([`InstancedTracer::intersect`]) and occlusion ([`InstancedTracer::occluded`]), each hit
/// naming its instance; rays may carry masks that leave instances out.
///
/// ```
/// use raytrail::core::scene::Scene;
/// use raytrail::{Instance, InstancedTracer, Ray, Transform, Vec3};
/// # fn main() -> Result<(), raytrail::Error> {
/// let triangle = Scene::from_indexed(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]])?;
/// // The triangle twice: where it is (id 10), and moved 2 down (id 20, mask bit 1 only).
/// let instances = [
///     Instance::new(0, Transform::IDENTITY).with_id(10),
///     Instance::new(0, Transform::translation([0.0, 0.0, -2.0])).with_id(20).with_mask(0b10),
/// ];
/// let tracer = InstancedTracer::new(&[triangle], &instances)?;
/// let ray = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z, 0.0, f32::INFINITY);
/// let hit = tracer.intersect(&[ray])?[0];
/// assert_eq!((hit.instance, hit.t), (10, 1.0));
/// // A ray below the first copy meets the second, unless its mask leaves that copy out.
/// let below = Ray { origin: [0.25, 0.25, -1.0], ..ray };
/// assert_eq!(tracer.intersect(&[below])?[0].instance, 20);
/// assert!(!tracer.intersect_masked(&[below], &[0b01])?[0].is_hit());
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct InstancedTracer {
    backend: CpuBackend,
    scene: InstancedScene<CpuScene>,
    method: Method,
    reject_untraceable: bool,
}

impl InstancedTracer {
    /// `instances` of `meshes` with the defaults (see [`TracerBuilder::build_instanced`]).
    pub fn new(meshes: &[Scene], instances: &[Instance]) -> Result<Self, Error> {
        TracerBuilder::default().build_instanced(meshes, instances)
    }

    pub(crate) fn build(b: TracerBuilder, meshes: &[Scene], instances: &[Instance]) -> Result<Self, Error> {
        let backend = b.backend()?;
        let method = b.method.unwrap_or(INSTANCED_DEFAULT);
        let prepared = meshes
            .iter()
            .map(|scene| Ok(Arc::new(PreparedScene::new(scene, b.tree.build(scene)?, &[method])?)))
            .collect::<Result<Vec<_>, Error>>()?;
        let scene = InstancedScene::prepare(&backend, &prepared, instances)?;
        Ok(Self { backend, scene, method, reject_untraceable: b.reject_untraceable })
    }

    /// The instances, in the order given.
    pub fn instances(&self) -> &[Instance] {
        self.scene.instances()
    }

    /// The method every instance is traced with.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The closest hit of each ray ([`InstanceHit::MISS`] where there is none).
    pub fn intersect(&self, rays: &[Ray]) -> Result<Vec<InstanceHit>, Error> {
        let mut hits = vec![InstanceHit::MISS; rays.len()];
        self.intersect_into(rays, None, &mut hits)?;
        Ok(hits)
    }

    /// The closest hit of each ray among the instances its mask admits (`masks[i] & mask != 0`;
    /// one mask per ray).
    pub fn intersect_masked(&self, rays: &[Ray], masks: &[u32]) -> Result<Vec<InstanceHit>, Error> {
        let mut hits = vec![InstanceHit::MISS; rays.len()];
        self.intersect_into(rays, Some(masks), &mut hits)?;
        Ok(hits)
    }

    /// The closest hit of each ray into `hits` (one slot per ray), with masks where given; the
    /// report counts the refused rays and the rays traced into each instance.
    pub fn intersect_into(
        &self,
        rays: &[Ray],
        masks: Option<&[u32]>,
        hits: &mut [InstanceHit],
    ) -> Result<InstancedReport, Error> {
        self.trace(rays, masks, Query::Closest, hits)
    }

    /// Whether anything blocks each ray within its interval.
    pub fn occluded(&self, rays: &[Ray]) -> Result<Vec<bool>, Error> {
        self.occlusion(rays, None)
    }

    /// Whether anything among the instances its mask admits blocks each ray.
    pub fn occluded_masked(&self, rays: &[Ray], masks: &[u32]) -> Result<Vec<bool>, Error> {
        self.occlusion(rays, Some(masks))
    }

    /// Whether anything blocks each ray into `blocked` (one slot per ray), with masks where
    /// given; a refused ray is `false` there and counted in the report.
    pub fn occluded_into(
        &self,
        rays: &[Ray],
        masks: Option<&[u32]>,
        blocked: &mut [bool],
    ) -> Result<InstancedReport, Error> {
        if blocked.len() != rays.len() {
            return Err(Error::Core(raytrail_core::Error::BufferMismatch { rays: rays.len(), hits: blocked.len() }));
        }
        let mut hits = vec![InstanceHit::MISS; rays.len()];
        let report = self.trace(rays, masks, Query::Any, &mut hits)?;
        for (b, h) in blocked.iter_mut().zip(&hits) {
            *b = h.is_hit();
        }
        Ok(report)
    }

    fn occlusion(&self, rays: &[Ray], masks: Option<&[u32]>) -> Result<Vec<bool>, Error> {
        let mut blocked = vec![false; rays.len()];
        self.occluded_into(rays, masks, &mut blocked)?;
        Ok(blocked)
    }

    fn trace(
        &self,
        rays: &[Ray],
        masks: Option<&[u32]>,
        query: Query,
        hits: &mut [InstanceHit],
    ) -> Result<InstancedReport, Error> {
        if self.reject_untraceable {
            if let Some(first) = rays.iter().position(|r| !r.is_traceable()) {
                let count = raytrail_core::trace::count_untraceable(&rays[first..]);
                return Err(Error::UntraceableRays { count, first });
            }
        }
        if hits.len() != rays.len() || masks.is_some_and(|m| m.len() != rays.len()) {
            let other = if hits.len() != rays.len() { hits.len() } else { masks.map_or(0, <[u32]>::len) };
            return Err(Error::Core(raytrail_core::Error::BufferMismatch { rays: rays.len(), hits: other }));
        }
        let options = TraceOptions::new(self.method).query(query);
        // The top-level walk and the waves are serial per call: chunks of rays run side by side
        // on the backend's threads (each chunk's per-instance batches still spread over them).
        let chunk = rays.len().div_ceil(4 * self.backend.threads()).max(MIN_CHUNK_RAYS);
        let parts = self.backend.install(|| {
            rays.par_chunks(chunk)
                .zip(hits.par_chunks_mut(chunk))
                .enumerate()
                .map(|(k, (r, h))| {
                    let m = masks.map(|m| &m[k * chunk..k * chunk + r.len()]);
                    trace_instanced(&self.backend, &self.scene, r, m, &options, h)
                })
                .collect::<Result<Vec<_>, _>>()
        })?;
        Ok(merged(parts, self.scene.instances().len()))
    }
}

/// The fewest rays a chunk of an instanced call holds: below it a chunk's own top-level walk
/// and per-instance calls cost more than the thread they gain.
const MIN_CHUNK_RAYS: usize = 1024;

/// The reports of a call's chunks as one.
fn merged(parts: Vec<InstancedReport>, instances: usize) -> InstancedReport {
    let mut out = InstancedReport { entered: vec![0; instances], ..Default::default() };
    for p in parts {
        out.report.rays += p.report.rays;
        out.report.refused += p.report.refused;
        out.report.untraceable += p.report.untraceable;
        out.backend_seconds += p.backend_seconds;
        out.waves = out.waves.max(p.waves);
        for (sum, n) in out.entered.iter_mut().zip(&p.entered) {
            *sum += n;
        }
    }
    out
}
