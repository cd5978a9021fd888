//! The backend-agnostic trace API: what every backend implements and every caller uses.

use crate::all_hits::{AllHits, AllHitsOptions};
use crate::method::{Method, Query};
use crate::nearest::NearestPoint;
use crate::observe::Counters;
use crate::prepared::PreparedScene;
use crate::stream::{StreamParams, StreamStats};
use crate::trace_order::TraceOrder;
use crate::{Error, Hit, Ray};
use alloc::sync::Arc;
use alloc::vec::Vec;

/// Which ray/triangle test to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TriangleTestKind {
    /// Woop, Benthin and Wald (2013): watertight, the default.
    #[default]
    Watertight,
    /// Möller and Trumbore (1997): fast, not watertight.
    MollerTrumbore,
}

/// What to record besides the hits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Record {
    /// Hits only: the fast path, no observer.
    #[default]
    Nothing,
    /// Work counters summed over the batch.
    Counters,
    /// Counters and every ray's node enumeration ([`PreparedScene::canonical_ids`]).
    Enumerations,
}

/// How to trace a batch. Built from a method and adjusted by the builder methods, so options can
/// grow without breaking callers:
///
/// ```
/// use raytrail_core::method::{Bvh2Method, Query};
/// use raytrail_core::trace::{Record, TraceOptions};
/// let options = TraceOptions::new(Bvh2Method::Hash).query(Query::Any).record(Record::Counters);
/// assert_eq!(options.query, Query::Any);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub struct TraceOptions {
    /// Traversal method.
    pub method: Method,
    /// Closest or any hit.
    pub query: Query,
    /// Triangle test.
    pub triangle_test: TriangleTestKind,
    /// What to record.
    pub record: Record,
    /// Parameters of the stream methods (ignored by the others).
    pub stream: StreamParams,
    /// The order the rays are traced in ([`TraceOrder`]): the hits are the same in any order.
    pub order: TraceOrder,
}

impl TraceOptions {
    /// Closest-hit tracing with `method`, watertight, recording nothing.
    pub fn new(method: impl Into<Method>) -> Self {
        Self {
            method: method.into(),
            query: Query::Closest,
            triangle_test: TriangleTestKind::Watertight,
            record: Record::Nothing,
            stream: StreamParams::default(),
            order: TraceOrder::AsGiven,
        }
    }

    /// The same options for `query`.
    pub fn query(mut self, query: Query) -> Self {
        self.query = query;
        self
    }

    /// The same options with `test` as the triangle test.
    pub fn triangle_test(mut self, test: TriangleTestKind) -> Self {
        self.triangle_test = test;
        self
    }

    /// The same options recording `record`.
    pub fn record(mut self, record: Record) -> Self {
        self.record = record;
        self
    }

    /// The same options with `params` for the stream methods.
    pub fn stream(mut self, params: StreamParams) -> Self {
        self.stream = params;
        self
    }

    /// The same options tracing the rays in `order`.
    pub fn order(mut self, order: TraceOrder) -> Self {
        self.order = order;
        self
    }
}

/// What a batch cost, and what was recorded: a field is `None` exactly when it was not asked for.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct Report {
    /// Rays traced.
    pub rays: usize,
    /// Wall-clock seconds of the call, end to end: for a device backend, transfers included (0
    /// where the backend has no clock).
    pub seconds: f64,
    /// Seconds the device spent in the trace's kernels alone (GPU timestamps), where a device
    /// backend measured them; `None` on the host backends and on adapters without timestamps.
    pub kernel_seconds: Option<f64>,
    /// Bytes copied between host and device memory by the call (0 on the host backends).
    pub transfer_bytes: u64,
    /// Work counters ([`Record::Counters`] and [`Record::Enumerations`]).
    pub counters: Option<Counters>,
    /// Per-ray node enumerations ([`Record::Enumerations`]).
    pub enumerations: Option<Vec<Vec<u32>>>,
    /// A stream method's working figures and stage times (stream methods only, always).
    pub stream: Option<StreamStats>,
    /// Rays refused: answered [`Hit::REFUSED`] because no method can answer them reliably
    /// ([`PreparedScene::frame_rays`]). Never counted as misses.
    pub refused: usize,
    /// Rays that cannot hit anything as given ([`Ray::is_traceable`] is false: a NaN or infinite
    /// component, a zero direction, a NaN bound or `tmin > tmax`), answered as misses.
    pub untraceable: usize,
}

impl Report {
    /// A report of `rays` rays traced in `seconds`, recording nothing.
    pub fn new(rays: usize, seconds: f64) -> Self {
        Self {
            rays,
            seconds,
            kernel_seconds: None,
            transfer_bytes: 0,
            counters: None,
            enumerations: None,
            stream: None,
            refused: 0,
            untraceable: 0,
        }
    }

    /// Millions of rays per second.
    pub fn mrays_per_s(&self) -> f64 {
        if self.seconds > 0.0 {
            self.rays as f64 / self.seconds / 1e6
        } else {
            0.0
        }
    }
}

/// Fails with [`Error::BufferMismatch`] unless there is one hit slot per ray: the first check of
/// every [`Trace::trace`].
pub fn check_buffers(rays: &[Ray], hits: &[Hit]) -> Result<(), Error> {
    if rays.len() == hits.len() {
        Ok(())
    } else {
        Err(Error::BufferMismatch { rays: rays.len(), hits: hits.len() })
    }
}

/// Traces a batch in `scene`'s frame ([`PreparedScene::frame_rays`]): checks the buffers, hands
/// the framed rays to `trace`, puts the hits back in the caller's frame and counts the refused
/// and the untraceable rays in the report. Every backend's [`Trace::trace`] goes through it, so
/// all of them scale, move, refuse and count rays alike.
pub fn trace_framed(
    scene: &PreparedScene,
    rays: &[Ray],
    hits: &mut [Hit],
    trace: impl FnOnce(&[Ray], &mut [Hit]) -> Result<Report, Error>,
) -> Result<Report, Error> {
    check_buffers(rays, hits)?;
    let framed = scene.frame_rays(rays);
    let mut report = trace(framed.rays(), hits)?;
    report.refused = framed.finish(hits);
    report.untraceable = count_untraceable(rays);
    Ok(report)
}

/// How many of `rays` are untraceable ([`Ray::is_traceable`] false), for [`Report::untraceable`]
/// ([`Ray::untraceable_flag`], no branch per ray).
#[inline]
pub fn count_untraceable(rays: &[Ray]) -> usize {
    rays.iter().map(|r| r.untraceable_flag() as usize).sum()
}

/// A backend: prepares a scene once, then traces batches of rays into hit buffers. Backends are
/// shared across threads (`Send + Sync`); a scene prepared by one backend is traced by it alone.
pub trait Trace: Send + Sync {
    /// The backend's own form of a scene (uploaded buffers, a shared reference, ...).
    type Prepared;
    /// Short name for reports.
    fn name(&self) -> &str;
    /// Whether the backend can trace with `method`; [`Trace::trace`] fails with
    /// [`Error::Unsupported`] for a method it cannot.
    fn supports(&self, method: Method) -> bool;
    /// Makes a prepared scene usable by this backend.
    fn prepare(&self, scene: Arc<PreparedScene>) -> Result<Self::Prepared, Error>;
    /// Traces `rays` into `hits` (same length), recording what `options` ask for.
    fn trace(
        &self,
        scene: &Self::Prepared,
        rays: &[Ray],
        options: &TraceOptions,
        hits: &mut [Hit],
    ) -> Result<Report, Error>;

    /// Every hit of each of `rays` in order of `t`, each triangle once, as `options` keep them
    /// ([`crate::all_hits`]): the lists the core's walk makes ([`AllHits::trace`]), bit for bit,
    /// which the conformance suite holds every backend to. A backend without the query keeps this
    /// default, [`Error::Unsupported`], and the suite reports it as not conforming.
    fn all_hits(&self, scene: &Self::Prepared, rays: &[Ray], options: &AllHitsOptions) -> Result<AllHits, Error> {
        let _ = (scene, rays, options);
        Err(Error::Unsupported { method: "all hits", by: "this backend" })
    }

    /// The point of the mesh nearest to each of `points` within distance `radius` (`None` where
    /// no triangle comes that close, or for a point that is not finite; [`crate::nearest`]): the
    /// core's answers ([`crate::nearest::nearest_points`]), bit for bit, which the conformance
    /// suite holds every backend to. A backend without the query keeps this default,
    /// [`Error::Unsupported`], and the suite reports it as not conforming.
    fn nearest_points(
        &self,
        scene: &Self::Prepared,
        points: &[[f32; 3]],
        radius: f32,
    ) -> Result<Vec<Option<NearestPoint>>, Error> {
        let _ = (scene, points, radius);
        Err(Error::Unsupported { method: "nearest points", by: "this backend" })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn the_untraceable_count_agrees_with_is_traceable_on_every_kind_of_bad_ray() {
        let values = [0.0, -0.0, 1.0, -2.5, 1e-40, f32::MAX, f32::INFINITY, f32::NEG_INFINITY, f32::NAN];
        let mut rays = Vec::new();
        for &a in &values {
            for &b in &values {
                rays.push(Ray::new(Vec3::new(a, 1.0, 2.0), Vec3::new(b, 0.0, 0.0), 0.0, f32::INFINITY));
                rays.push(Ray::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, a, b), 0.0, 1.0));
                rays.push(Ray::new(Vec3::ONE, Vec3::Z, a, b));
            }
        }
        for r in &rays {
            assert_eq!(r.untraceable_flag() == 0, r.is_traceable(), "{r:?}");
        }
        let expected = rays.iter().filter(|r| !r.is_traceable()).count();
        assert!(expected > 0 && expected < rays.len());
        assert_eq!(count_untraceable(&rays), expected);
    }
}
