//! The BVH2 methods' loop for one chunk, monomorphized per key width x triangle test x recording.

use crate::chunk::Chunk;
use raytrail_core::bvh2::traverse::{trace_batch, trace_ray, TraceRoot};
use raytrail_core::bvh2::SliceMemory;
use raytrail_core::intersect::{MollerTrumbore, TriangleTest, Watertight};
use raytrail_core::key::{Key, KeyWidth};
use raytrail_core::method::{Bvh2Method, Method};
use raytrail_core::observe::{Both, Counters, NoObserver, Recorder};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Record, TraceOptions, TriangleTestKind};
use raytrail_core::Error;

/// Traces one chunk with `method`; returns its counters (only `rays` is set when nothing is
/// recorded).
pub(crate) fn trace_chunk(
    scene: &PreparedScene,
    method: Bvh2Method,
    opts: &TraceOptions,
    chunk: Chunk<'_>,
) -> Result<Counters, Error> {
    let run = Run { scene, method, opts, mem: scene.memory(method)?, root: scene.root(method)? };
    match (scene.key_width(), opts.triangle_test) {
        (KeyWidth::W32, TriangleTestKind::Watertight) => run.go::<u32, Watertight>(chunk),
        (KeyWidth::W32, TriangleTestKind::MollerTrumbore) => run.go::<u32, MollerTrumbore>(chunk),
        (KeyWidth::W64, TriangleTestKind::Watertight) => run.go::<u64, Watertight>(chunk),
        (KeyWidth::W64, TriangleTestKind::MollerTrumbore) => run.go::<u64, MollerTrumbore>(chunk),
    }
}

struct Run<'a> {
    scene: &'a PreparedScene,
    method: Bvh2Method,
    opts: &'a TraceOptions,
    mem: SliceMemory<'a>,
    root: TraceRoot,
}

impl Run<'_> {
    fn go<K: Key, T: TriangleTest>(&self, chunk: Chunk<'_>) -> Result<Counters, Error> {
        let (method, query) = (self.method, self.opts.query);
        let mut counters = Counters::default();
        match self.opts.record {
            Record::Nothing => {
                trace_batch::<K, _, T, _>(method, &self.mem, self.root, chunk.rays, chunk.hits, query, &mut NoObserver);
            }
            Record::Counters => {
                trace_batch::<K, _, T, _>(method, &self.mem, self.root, chunk.rays, chunk.hits, query, &mut counters);
            }
            Record::Enumerations => {
                let slots = chunk.rays.iter().zip(chunk.hits.iter_mut()).zip(chunk.enumerations.iter_mut());
                for ((ray, hit), nodes) in slots {
                    let mut obs = Both(counters, Recorder::default());
                    *hit = trace_ray::<K, _, T, _>(method, &self.mem, self.root, ray, query, &mut obs);
                    counters = obs.0;
                    *nodes = self.scene.canonical_ids(Method::Bvh2(method), obs.1.nodes.iter().copied())?;
                }
            }
        }
        counters.rays = chunk.rays.len() as u64;
        Ok(counters)
    }
}
