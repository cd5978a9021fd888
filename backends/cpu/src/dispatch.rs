//! Picks the monomorphized traversal loop for a batch: key width x triangle test x recording.

use raytrail_core::bvh2::{BinaryLayout, SliceMemory};
use raytrail_core::intersect::{MollerTrumbore, TriangleTest, Watertight};
use raytrail_core::key::{Key, KeyWidth};
use raytrail_core::observe::{Both, Counters, NoObserver, Recorder};
use raytrail_core::prepared::PreparedBvh2;
use raytrail_core::trace::{Record, TraceOptions, TriangleTestKind};
use raytrail_core::traverse::{trace_batch, trace_ray, Family, TraceRoot};
use raytrail_core::{Error, Hit, Ray};

/// One chunk's rays, hit slots and (when recorded) enumeration slots.
pub(crate) struct Chunk<'a> {
    pub rays: &'a [Ray],
    pub hits: &'a mut [Hit],
    pub enumerations: &'a mut [Vec<u32>],
}

/// Traces one chunk; returns its counters (only `rays` is set when nothing is recorded).
pub(crate) fn trace_chunk(scene: &PreparedBvh2, opts: &TraceOptions, chunk: Chunk<'_>) -> Result<Counters, Error> {
    if opts.method.family() == Family::Kd {
        return crate::dispatch_kd::trace_kd_chunk(scene, opts, chunk);
    }
    let mem = scene.memory(opts.method)?;
    let root = scene.root(opts.method)?;
    let layout = scene.layout(opts.method)?;
    let run = Run { opts, mem, root, layout };
    Ok(match (scene.key_width(), opts.triangle_test) {
        (KeyWidth::W32, TriangleTestKind::Watertight) => run.go::<u32, Watertight>(chunk),
        (KeyWidth::W32, TriangleTestKind::MollerTrumbore) => run.go::<u32, MollerTrumbore>(chunk),
        (KeyWidth::W64, TriangleTestKind::Watertight) => run.go::<u64, Watertight>(chunk),
        (KeyWidth::W64, TriangleTestKind::MollerTrumbore) => run.go::<u64, MollerTrumbore>(chunk),
    })
}

struct Run<'a> {
    opts: &'a TraceOptions,
    mem: SliceMemory<'a>,
    root: TraceRoot,
    layout: &'a BinaryLayout,
}

impl Run<'_> {
    fn go<K: Key, T: TriangleTest>(&self, chunk: Chunk<'_>) -> Counters {
        let (method, query) = (self.opts.method, self.opts.query);
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
                    *nodes = obs.1.nodes.iter().map(|&r| self.layout.canonical_id(r).unwrap_or(u32::MAX)).collect();
                }
            }
        }
        counters.rays = chunk.rays.len() as u64;
        counters
    }
}
