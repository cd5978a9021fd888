//! All hits along each ray of a batch ([`raytrail_core::all_hits`]) on the backend's threads:
//! chunks of rays traced in parallel, their lists joined in ray order.

use crate::{CpuBackend, CpuScene};
use rayon::prelude::*;
use raytrail_core::all_hits::{AllHits, AllHitsOptions};
use raytrail_core::{Error, Ray};

/// Rays per task: enough that a task's list buffer and stack are reused over many rays, few
/// enough that two threads share a batch of a few thousand rays.
const CHUNK: usize = 256;

impl CpuBackend {
    /// [`Trace::all_hits`](raytrail_core::trace::Trace::all_hits) on this backend's threads.
    /// [`Error::NotPrepared`] for a scene without a wide tree (one prepared only for BVH2, kd or
    /// stream methods).
    pub(crate) fn trace_all_hits(
        &self,
        scene: &CpuScene,
        rays: &[Ray],
        options: &AllHitsOptions,
    ) -> Result<AllHits, Error> {
        let prepared = &scene.0;
        // Fails here, once, for a scene without a wide tree.
        prepared.query_tree()?;
        let parts: Vec<Result<AllHits, Error>> =
            self.install(|| rays.par_chunks(CHUNK).map(|chunk| AllHits::trace(prepared, chunk, options)).collect());
        let mut out = AllHits::default();
        for part in parts {
            out.append(part?);
        }
        Ok(out)
    }
}
