//! The stackless wide method's loop for one chunk ([`raytrail_core::wide::trail`]), monomorphized
//! per key width x triangle test x recording, in the AVX2-compiled loop where the processor has
//! AVX2 (as the stack traversal's, so the two compare on equal terms).

use crate::chunk::Chunk;
use crate::record::{record, with_test, Independent, RayLoop, WithTest};
use core::marker::PhantomData;
use raytrail_core::intersect::TriangleTest;
use raytrail_core::key::{Key, KeyWidth};
use raytrail_core::method::{Method, Query, WideMethod};
use raytrail_core::observe::{Counters, Observer};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::TraceOptions;
use raytrail_core::wide::keyed::WideKeyedMemory;
use raytrail_core::wide::trail::trace_wide_trail_batch;
use raytrail_core::wide::traverse::WideRoot;
use raytrail_core::wide::FastKernel;
use raytrail_core::{Error, Hit, Ray};

/// Traces one chunk with the trail walk `method`.
pub(crate) fn trace_chunk(
    scene: &PreparedScene,
    method: WideMethod,
    opts: &TraceOptions,
    chunk: Chunk<'_>,
) -> Result<Counters, Error> {
    let (mem, keys) = scene.wide_keyed(method)?;
    let (mem, test) = (&mem, opts.triangle_test);
    match keys {
        KeyWidth::W32 => with_test(test, ByTest::<u32, _> { scene, method, opts, mem, chunk, key: PhantomData }),
        KeyWidth::W64 => with_test(test, ByTest::<u64, _> { scene, method, opts, mem, chunk, key: PhantomData }),
    }
}

/// A trail chunk waiting for its triangle test.
struct ByTest<'a, 'm, 'c, K, M> {
    scene: &'a PreparedScene,
    method: WideMethod,
    opts: &'a TraceOptions,
    mem: &'m M,
    chunk: Chunk<'c>,
    key: PhantomData<K>,
}

impl<K: Key, M: WideKeyedMemory<4>> WithTest for ByTest<'_, '_, '_, K, M> {
    type Output = Result<Counters, Error>;
    fn with<T: TriangleTest>(self) -> Self::Output {
        let ByTest { scene, method, opts, mem, chunk, .. } = self;
        let b = TrailBatch::<4, K, M, T> { mem, root: scene.wide_root(method)?, query: opts.query, types: PhantomData };
        record(scene, Method::Wide(method), opts.record, chunk, &Independent(&b))
    }
}

/// The trail walk's loop over a slice of rays.
struct TrailBatch<'m, const W: usize, K, M, T> {
    mem: &'m M,
    root: WideRoot,
    query: Query,
    types: PhantomData<(K, T)>,
}

impl<const W: usize, K: Key, M: WideKeyedMemory<W>, T: TriangleTest> RayLoop for TrailBatch<'_, W, K, M, T> {
    fn trace<O: Observer>(&self, rays: &[Ray], hits: &mut [Hit], obs: &mut O) {
        let (mem, root, query) = (self.mem, self.root, self.query);
        #[cfg(target_arch = "x86_64")]
        if crate::x86::available() {
            // SAFETY: the processor has AVX2 (checked just above).
            unsafe { crate::x86::single_ray::trace_trail_batch::<W, K, M, T, O>(mem, root, rays, hits, query, obs) };
            return;
        }
        trace_wide_trail_batch::<W, K, M, T, FastKernel, O>(mem, root, rays, hits, query, obs);
    }
}
