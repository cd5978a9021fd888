//! The wide-BVH methods' loop for one chunk, monomorphized per width x triangle test x recording,
//! with the fast child kernel (SIMD box tests, the sorting network).

use crate::chunk::Chunk;
use raytrail_core::intersect::{MollerTrumbore, TriangleTest, Watertight};
use raytrail_core::method::{Method, WideMethod};
use raytrail_core::observe::{Both, Counters, NoObserver, Recorder};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Record, TraceOptions, TriangleTestKind};
use raytrail_core::wide::traverse::{trace_wide_batch, trace_wide_ray, WideRoot};
use raytrail_core::wide::{FastKernel, WideSliceMemory};
use raytrail_core::Error;

/// Traces one chunk with `method`; returns its counters.
pub(crate) fn trace_chunk(
    scene: &PreparedScene,
    method: WideMethod,
    opts: &TraceOptions,
    chunk: Chunk<'_>,
) -> Result<Counters, Error> {
    let root = scene.wide_root(method)?;
    match method.width() {
        4 => go(scene, method, opts, &scene.wide4(method)?.memory(), root, chunk),
        _ => go(scene, method, opts, &scene.wide8(method)?.memory(), root, chunk),
    }
}

fn go<const W: usize>(
    scene: &PreparedScene,
    method: WideMethod,
    opts: &TraceOptions,
    mem: &WideSliceMemory<'_, W>,
    root: WideRoot,
    chunk: Chunk<'_>,
) -> Result<Counters, Error> {
    match opts.triangle_test {
        TriangleTestKind::Watertight => run::<W, Watertight>(scene, method, opts, mem, root, chunk),
        TriangleTestKind::MollerTrumbore => run::<W, MollerTrumbore>(scene, method, opts, mem, root, chunk),
    }
}

fn run<const W: usize, T: TriangleTest>(
    scene: &PreparedScene,
    method: WideMethod,
    opts: &TraceOptions,
    mem: &WideSliceMemory<'_, W>,
    root: WideRoot,
    chunk: Chunk<'_>,
) -> Result<Counters, Error> {
    let query = opts.query;
    let mut counters = Counters::default();
    match opts.record {
        Record::Nothing => {
            trace_wide_batch::<W, _, T, FastKernel, _>(mem, root, chunk.rays, chunk.hits, query, &mut NoObserver)
        }
        Record::Counters => {
            trace_wide_batch::<W, _, T, FastKernel, _>(mem, root, chunk.rays, chunk.hits, query, &mut counters)
        }
        Record::Enumerations => {
            let slots = chunk.rays.iter().zip(chunk.hits.iter_mut()).zip(chunk.enumerations.iter_mut());
            for ((ray, hit), nodes) in slots {
                let mut obs = Both(counters, Recorder::default());
                *hit = trace_wide_ray::<W, _, T, FastKernel, _>(mem, root, ray, query, &mut obs);
                counters = obs.0;
                *nodes = scene.canonical_ids(Method::Wide(method), obs.1.nodes.iter().copied())?;
            }
        }
    }
    counters.rays = chunk.rays.len() as u64;
    Ok(counters)
}
