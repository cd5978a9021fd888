//! The backend-agnostic trace API.

use crate::observe::Counters;
use crate::prepared::PreparedBvh2;
use crate::traverse::{Method, Query};
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
    /// Counters and every ray's node enumeration (canonical node ids in visiting order).
    Enumerations,
}

/// How to trace a batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TraceOptions {
    /// Traversal method.
    pub method: Method,
    /// Closest or any hit.
    pub query: Query,
    /// Triangle test.
    pub triangle_test: TriangleTestKind,
    /// What to record.
    pub record: Record,
}

impl TraceOptions {
    /// Closest-hit tracing with `method`, watertight, recording nothing.
    pub fn new(method: Method) -> Self {
        Self { method, query: Query::Closest, triangle_test: TriangleTestKind::Watertight, record: Record::Nothing }
    }
}

/// What a batch cost.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Report {
    /// Rays traced.
    pub rays: usize,
    /// Wall-clock seconds of the traversal (0 where the backend has no clock).
    pub seconds: f64,
    /// Work counters, when recorded.
    pub counters: Option<Counters>,
    /// Per-ray node enumerations (canonical ids), when recorded; empty otherwise.
    pub enumerations: Vec<Vec<u32>>,
}

impl Report {
    /// Millions of rays per second.
    pub fn mrays_per_s(&self) -> f64 {
        if self.seconds > 0.0 {
            self.rays as f64 / self.seconds / 1e6
        } else {
            0.0
        }
    }
}

/// A backend: prepares a scene once, then traces batches of rays into hit buffers.
pub trait Trace {
    /// The backend's own form of a scene (uploaded buffers, a shared reference, ...).
    type Prepared;
    /// Short name for reports.
    fn name(&self) -> &str;
    /// Makes a prepared scene usable by this backend.
    fn prepare(&self, scene: Arc<PreparedBvh2>) -> Result<Self::Prepared, Error>;
    /// Traces `rays` into `hits` (same length), recording what `options` ask for.
    fn trace(
        &self,
        scene: &Self::Prepared,
        rays: &[Ray],
        options: &TraceOptions,
        hits: &mut [Hit],
    ) -> Result<Report, Error>;
}
