//! What the queries beyond a hit per ray share on the device (all hits along a ray,
//! `all_hits.rs`; the nearest point, `nearest.rs`): the scene's tree they walk, the one the core's
//! walks read, and one launch of their kernel over a batch of work items on the grid.

use crate::batch;
use crate::compose::{Answer, DispatchKind, Variant};
use crate::config::{Dispatch, GpuConfig};
use crate::device::device_error;
use crate::launch;
use crate::params::Params;
use crate::scene::WgpuScene;
use crate::WgpuBackend;
use raytrail_core::key::KeyWidth;
use raytrail_core::method::{Method, Query, WideMethod};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Record, TraceOptions, TriangleTestKind};
use raytrail_core::{Error, Hit, Ray};

/// The methods whose trees the core's queries read, in the order it prefers them
/// ([`PreparedScene::query_tree`]): the device walks the same tree.
const QUERY_TREES: [WideMethod; 4] = [WideMethod::BVH8_SAH, WideMethod::BVH8, WideMethod::BVH4, WideMethod::BVH4_NAIVE];

/// The wide method whose tree [`PreparedScene::query_tree`] names; its error for a scene without
/// a wide tree.
pub(crate) fn query_method(prepared: &PreparedScene) -> Result<WideMethod, Error> {
    prepared.query_tree()?;
    QUERY_TREES
        .into_iter()
        .find(|&m| prepared.wide_root(m).is_ok())
        .ok_or(Error::NotPrepared { method: "the queries of the wide tree", missing: "a wide tree" })
}

impl WgpuBackend {
    /// Runs the `answer` kernel of `method`'s tree over `items` (one per invocation, on the
    /// grid) with `stride` record words each and the parameters `params` sets; returns the hits
    /// and the records, in item order.
    pub(crate) fn run_wide_query(
        &self,
        scene: &WgpuScene,
        method: WideMethod,
        answer: Answer,
        items: &[Ray],
        stride: usize,
        params: impl FnOnce(&mut Params),
    ) -> Result<(Vec<Hit>, Vec<u32>), Error> {
        let binding = self.gpu.limits.max_storage_buffer_binding_size.min(self.gpu.limits.max_buffer_size);
        if 4 * stride as u64 > binding {
            return Err(device_error(format!(
                "{stride} record words per work item exceed the device's largest binding ({binding} bytes): \
                 ask for fewer hits per ray (max_hits)"
            )));
        }
        let variant = Variant {
            method: Method::Wide(method),
            keys: KeyWidth::W32,
            triangle: TriangleTestKind::Watertight,
            query: Query::Closest,
            record: Record::Nothing,
            dispatch: DispatchKind::Grid,
            workgroup_size: self.config.workgroup_size,
            answer,
        };
        let pipeline = self.pipelines.get(&self.gpu, &variant)?;
        let config = GpuConfig { dispatch: Dispatch::Grid, ..self.config };
        let options = TraceOptions::new(method);
        let mut launch = launch::launch(scene, &options, 0, &pipeline, &self.pipelines.bind_layout, config)?;
        launch.params.record_stride = stride as u32;
        params(&mut launch.params);
        let mut ws = scene.workspace()?;
        let mut hits = vec![Hit::MISS; items.len()];
        let records = batch::run(&self.gpu, &mut ws, &launch, items, &mut hits)?.records;
        Ok((hits, records))
    }
}
