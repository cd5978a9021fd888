//! The nearest point on the mesh to each of a batch of points ([`raytrail_core::nearest`]) on the
//! backend's threads.

use crate::{CpuBackend, CpuScene};
use rayon::prelude::*;
use raytrail_core::nearest::{nearest_points, NearestPoint};
use raytrail_core::Error;

/// Points per task.
const CHUNK: usize = 256;

impl CpuBackend {
    /// [`Trace::nearest_points`](raytrail_core::trace::Trace::nearest_points) on this backend's
    /// threads. [`Error::NotPrepared`] for a scene without a wide tree.
    pub(crate) fn trace_nearest_points(
        &self,
        scene: &CpuScene,
        points: &[[f32; 3]],
        radius: f32,
    ) -> Result<Vec<Option<NearestPoint>>, Error> {
        let prepared = &scene.0;
        prepared.query_tree()?;
        let parts: Vec<Result<Vec<Option<NearestPoint>>, Error>> =
            self.install(|| points.par_chunks(CHUNK).map(|c| nearest_points(prepared, c, radius)).collect());
        let mut out = Vec::with_capacity(points.len());
        for part in parts {
            out.extend(part?);
        }
        Ok(out)
    }
}
