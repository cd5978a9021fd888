//! The stream method on the CPU: the core's pipeline with its stages mapped over rayon, the fast
//! leaf test (four triangles at once).

use rayon::prelude::*;
use raytrail_core::method::StreamMethod;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::stream::sort::Chunks;
use raytrail_core::stream::{trace_stream_with, FrustumCull, Parallel, StreamOutput};
use raytrail_core::trace::TraceOptions;
use raytrail_core::wide::FastKernel;
use raytrail_core::{Error, Hit, Ray};

/// Stage items (and a refit's passes, [`crate::refit`]) on rayon's current pool.
pub(crate) struct Rayon;

/// From this many items on, a task takes at least [`MIN_PER_TASK`] of them: such stages map cheap
/// items (a ray's key), and one per task would cost more in scheduling than in work. Fewer items
/// are heavy ones (a run of 2048 traversal pairs, a packet), and each may be a task of its own:
/// a limit of 512 items here once left a traversal level of 244 runs on one thread.
const MANY_ITEMS: usize = 1 << 16;

/// Items per task in a stage of [`MANY_ITEMS`] or more.
const MIN_PER_TASK: usize = 64;

impl Parallel for Rayon {
    fn map<T: Send>(&self, n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
        let min = if n >= MANY_ITEMS { MIN_PER_TASK } else { 1 };
        (0..n).into_par_iter().with_min_len(min).map(f).collect()
    }

    fn for_each_chunk<T: Send>(&self, data: &mut [T], chunk: usize, f: impl Fn(usize, &mut [T]) + Sync + Send) {
        data.par_chunks_mut(chunk.max(1)).enumerate().for_each(|(i, piece)| f(i, piece));
    }

    /// A parallel sort of (key, chunk index) pairs packed in a `u64`: the chunks come in base
    /// order, so this is the radix sort's order (by key, then base), on both cores.
    fn sort_chunks(&self, chunks: &mut Chunks) {
        let mut packed: Vec<u64> = chunks.key.iter().enumerate().map(|(i, &k)| u64::from(k) << 32 | i as u64).collect();
        packed.par_sort_unstable();
        let (base, size) = (chunks.base.clone(), chunks.size.clone());
        for (at, &p) in packed.iter().enumerate() {
            let i = (p & 0xffff_ffff) as usize;
            (chunks.key[at], chunks.base[at], chunks.size[at]) = ((p >> 32) as u32, base[i], size[i]);
        }
    }
}

/// Traces the whole batch (call inside the backend's pool).
pub(crate) fn trace(
    scene: &PreparedScene,
    method: StreamMethod,
    opts: &TraceOptions,
    rays: &[Ray],
    hits: &mut [Hit],
) -> Result<StreamOutput, Error> {
    let s = scene.stream_scene(method)?;
    trace_stream_with::<_, FrustumCull, FastKernel>(&Rayon, &s, rays, hits, opts, false)
}
