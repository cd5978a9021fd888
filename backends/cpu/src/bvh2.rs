//! The BVH2 methods' loop for one chunk, monomorphized per key width x triangle test x recording.

use crate::chunk::Chunk;
use crate::record::{record, with_test, Independent, RayLoop, WithTest};
use core::marker::PhantomData;
use raytrail_core::bvh2::traverse::{trace_batch, TraceRoot};
use raytrail_core::bvh2::SliceMemory;
use raytrail_core::intersect::TriangleTest;
use raytrail_core::key::{Key, KeyWidth};
use raytrail_core::method::{Bvh2Method, Method, Query};
use raytrail_core::observe::{Counters, Observer};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::TraceOptions;
use raytrail_core::{Error, Hit, Ray};

/// Traces one chunk with `method`; returns its counters (only `rays` is set when nothing is
/// recorded).
pub(crate) fn trace_chunk(
    scene: &PreparedScene,
    method: Bvh2Method,
    opts: &TraceOptions,
    chunk: Chunk<'_>,
) -> Result<Counters, Error> {
    let (mem, root) = (scene.memory(method)?, scene.root(method)?);
    let run = Run { scene, method, opts, mem, root, chunk };
    match scene.key_width() {
        KeyWidth::W32 => with_test(opts.triangle_test, Keyed::<u32>(run, PhantomData)),
        KeyWidth::W64 => with_test(opts.triangle_test, Keyed::<u64>(run, PhantomData)),
    }
}

/// What a chunk is traced with.
struct Run<'a, 'c> {
    scene: &'a PreparedScene,
    method: Bvh2Method,
    opts: &'a TraceOptions,
    mem: SliceMemory<'a>,
    root: TraceRoot,
    chunk: Chunk<'c>,
}

/// [`Run`] with the key width `K`, waiting for its triangle test.
struct Keyed<'a, 'c, K>(Run<'a, 'c>, PhantomData<K>);

impl<K: Key> WithTest for Keyed<'_, '_, K> {
    type Output = Result<Counters, Error>;
    fn with<T: TriangleTest>(self) -> Self::Output {
        let Run { scene, method, opts, mem, root, chunk } = self.0;
        let batch = Batch::<K, T> { method, mem, root, query: opts.query, types: PhantomData };
        record(scene, Method::Bvh2(method), opts.record, chunk, &Independent(&batch))
    }
}

/// The batch loop over a slice of rays ([`trace_batch`]).
struct Batch<'a, K, T> {
    method: Bvh2Method,
    mem: SliceMemory<'a>,
    root: TraceRoot,
    query: Query,
    types: PhantomData<(K, T)>,
}

impl<K: Key, T: TriangleTest> RayLoop for Batch<'_, K, T> {
    #[inline(always)]
    fn trace<O: Observer>(&self, rays: &[Ray], hits: &mut [Hit], obs: &mut O) {
        trace_batch::<K, _, T, _>(self.method, &self.mem, self.root, rays, hits, self.query, obs);
    }
}
