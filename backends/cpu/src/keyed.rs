//! The stackless wide method's loop for one chunk ([`raytrail_core::wide::trail`]), monomorphized
//! per key width x triangle test x recording, in the AVX2-compiled loop where the processor has
//! AVX2 (as the stack traversal's, so the two compare on equal terms).

use crate::chunk::Chunk;
use crate::wide::{record_rays, RayLoop};
use core::marker::PhantomData;
use raytrail_core::intersect::{MollerTrumbore, TriangleTest, Watertight};
use raytrail_core::key::{Key, KeyWidth};
use raytrail_core::method::{Query, WideMethod};
use raytrail_core::observe::{Counters, Observer};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{TraceOptions, TriangleTestKind};
use raytrail_core::wide::keyed::WideKeyedMemory;
use raytrail_core::wide::trail::trace_wide_trail_batch;
use raytrail_core::wide::traverse::WideRoot;
use raytrail_core::wide::FastKernel;
use raytrail_core::{Error, Hit, Ray};

/// Traces one chunk with the keyed `method`.
pub(crate) fn trace_chunk(
    scene: &PreparedScene,
    method: WideMethod,
    opts: &TraceOptions,
    chunk: Chunk<'_>,
) -> Result<Counters, Error> {
    let (mem, keys) = scene.wide_keyed(method)?;
    match keys {
        KeyWidth::W32 => by_test::<u32, _>(scene, method, opts, &mem, chunk),
        KeyWidth::W64 => by_test::<u64, _>(scene, method, opts, &mem, chunk),
    }
}

fn by_test<K: Key, M: WideKeyedMemory<4>>(
    scene: &PreparedScene,
    method: WideMethod,
    opts: &TraceOptions,
    mem: &M,
    chunk: Chunk<'_>,
) -> Result<Counters, Error> {
    let (root, query) = (scene.wide_root(method)?, opts.query);
    match opts.triangle_test {
        TriangleTestKind::Watertight => {
            let b = KeyedBatch::<4, K, M, Watertight> { mem, root, query, types: PhantomData };
            record_rays(scene, method, opts.record, chunk, &b)
        }
        TriangleTestKind::MollerTrumbore => {
            let b = KeyedBatch::<4, K, M, MollerTrumbore> { mem, root, query, types: PhantomData };
            record_rays(scene, method, opts.record, chunk, &b)
        }
    }
}

/// The keyed traversal's loop over a slice of rays.
struct KeyedBatch<'m, const W: usize, K, M, T> {
    mem: &'m M,
    root: WideRoot,
    query: Query,
    types: PhantomData<(K, T)>,
}

impl<const W: usize, K: Key, M: WideKeyedMemory<W>, T: TriangleTest> RayLoop for KeyedBatch<'_, W, K, M, T> {
    fn trace<O: Observer>(&self, rays: &[Ray], hits: &mut [Hit], obs: &mut O) {
        let (mem, root, query) = (self.mem, self.root, self.query);
        #[cfg(target_arch = "x86_64")]
        if crate::avx::available() {
            // SAFETY: the processor has AVX2 (checked just above).
            unsafe { crate::avx::trace_keyed_batch::<W, K, M, T, O>(mem, root, rays, hits, query, obs) };
            return;
        }
        trace_wide_trail_batch::<W, K, M, T, FastKernel, O>(mem, root, rays, hits, query, obs);
    }
}
