//! The point of the mesh nearest to each query point on the device
//! ([`Trace::nearest_points`](raytrail_core::trace::Trace::nearest_points)): shaders/nearest.wgsl
//! on the tree the core's walk reads, each point framed and each answer put back as the core does
//! ([`raytrail_core::nearest::nearest_point`]); the square root of the squared distance is taken
//! here, correctly rounded as on the CPU (WGSL's `sqrt` need not be).

use crate::compose::Answer;
use crate::scene::WgpuScene;
use crate::wide_query::query_method;
use crate::WgpuBackend;
use raytrail_core::nearest::{framed_query, query_bound, unframed, NearestPoint};
use raytrail_core::{Error, Ray};

/// Record words per query: the point.
const POINT_WORDS: usize = 3;

impl WgpuBackend {
    /// [`Trace::nearest_points`](raytrail_core::trace::Trace::nearest_points) on the device.
    pub(crate) fn trace_nearest_points(
        &self,
        scene: &WgpuScene,
        points: &[[f32; 3]],
        radius: f32,
    ) -> Result<Vec<Option<NearestPoint>>, Error> {
        let prepared = &scene.prepared;
        let method = query_method(prepared)?;
        // A query as the kernel reads it: the point in the scene's frame, and the squared
        // distance not to exceed (negative: no answer, as the core's walk gives none).
        let queries: Vec<Ray> = points
            .iter()
            .map(|&p| {
                let (q, r) = framed_query(prepared, p, radius);
                let bound = query_bound(q, r).unwrap_or(-1.0);
                Ray {
                    origin: q.to_array().map(|x| if x.is_finite() { x } else { 0.0 }),
                    tmin: 0.0,
                    dir: [0.0; 3],
                    tmax: bound,
                }
            })
            .collect();
        let (hits, records) = self.run_wide_query(scene, method, Answer::Nearest, &queries, POINT_WORDS, |_| {})?;
        Ok(hits
            .iter()
            .zip(records.chunks_exact(POINT_WORDS))
            .map(|(h, point)| {
                h.is_hit().then(|| {
                    let found = NearestPoint {
                        prim: h.prim,
                        u: h.u,
                        v: h.v,
                        point: [0, 1, 2].map(|k| f32::from_bits(point[k])),
                        distance: h.t.sqrt(),
                    };
                    unframed(prepared, found)
                })
            })
            .collect())
    }
}
