//! The stream kernels' binding layout and their compiled pipelines, made on first use.

use super::compose::StreamKernel;
use crate::device::{device_error, Gpu};
use crate::pipelines::buffer_layout;
use raytrail_core::method::StreamMethod;
use raytrail_core::trace::TraceOptions;
use raytrail_core::Error;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Arrays a stream kernel binds after the prelude's buffers and the stage uniform (bindings 8
/// and up; the radix scatter and the traversal kernels use all seven).
pub(crate) const STAGE_ARRAYS: usize = 7;

/// Storage buffers of the layout: the prelude's six and the stage arrays.
const STORAGE_BUFFERS: u32 = 6 + STAGE_ARRAYS as u32;

/// The layout every stream kernel shares and the kernels compiled so far.
pub(crate) struct StreamKernels {
    pub bind_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    compiled: Mutex<HashMap<StreamKernel, Arc<wgpu::ComputePipeline>>>,
}

impl StreamKernels {
    /// The layout: shaders/prelude.wgsl's seven bindings, the stage uniform (7), then
    /// [`STAGE_ARRAYS`] read-write arrays. Fails on an adapter with fewer storage buffers per
    /// stage than that needs.
    pub fn new(gpu: &Gpu) -> Result<StreamKernels, Error> {
        let have = gpu.limits.max_storage_buffers_per_shader_stage;
        if have < STORAGE_BUFFERS {
            return Err(device_error(format!(
                "the stream method's kernels bind {STORAGE_BUFFERS} storage buffers; the adapter allows {have}"
            )));
        }
        let (read, write) = (Some(true), Some(false));
        let mut kinds = vec![None, read, write, read, read, read, write, None];
        kinds.extend(std::iter::repeat_n(write, STAGE_ARRAYS));
        let (bind_layout, layout) = buffer_layout(gpu, "raytrail stream", &kinds);
        Ok(StreamKernels { bind_layout, layout, compiled: Mutex::new(HashMap::new()) })
    }

    /// Compiles every stage kernel and the intersection kernel of a trace with `options`.
    pub fn warm_up(&self, gpu: &Gpu, method: StreamMethod, options: &TraceOptions) -> Result<(), Error> {
        for k in StreamKernel::STAGES.into_iter().chain([StreamKernel::intersect(method, options)]) {
            self.get(gpu, k)?;
        }
        Ok(())
    }

    /// The pipeline of `k`, compiled now if it was not yet.
    pub fn get(&self, gpu: &Gpu, k: StreamKernel) -> Result<Arc<wgpu::ComputePipeline>, Error> {
        let poisoned = || device_error("the stream kernel cache was poisoned by a panic in another thread");
        if let Some(p) = self.compiled.lock().map_err(|_| poisoned())?.get(&k) {
            return Ok(p.clone());
        }
        let pipeline = Arc::new(gpu.compute_pipeline(&k.label(), &k.source()?, &k.overrides(), &self.layout)?);
        self.compiled.lock().map_err(|_| poisoned())?.insert(k, pipeline.clone());
        Ok(pipeline)
    }
}
