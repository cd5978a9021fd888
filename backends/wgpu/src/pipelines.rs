//! Kernels compiled on first use and kept: one per [`Variant`] a caller asks for.

use crate::compose::Variant;
use crate::device::Gpu;
use raytrail_core::Error;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// The bind group layout every kernel shares (shaders/prelude.wgsl) and the compiled kernels.
pub(crate) struct Pipelines {
    pub bind_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    compiled: Mutex<HashMap<Variant, Arc<wgpu::ComputePipeline>>>,
}

/// A one-group layout of buffer bindings `0..kinds.len()` (`read_only: None` is a uniform), and the
/// pipeline layout of that group: what every kernel, and the numerics probe, binds.
pub(crate) fn buffer_layout(
    gpu: &Gpu,
    label: &str,
    kinds: &[Option<bool>],
) -> (wgpu::BindGroupLayout, wgpu::PipelineLayout) {
    let entries: Vec<_> = (0u32..)
        .zip(kinds)
        .map(|(binding, kind)| {
            entry(
                binding,
                match *kind {
                    None => wgpu::BufferBindingType::Uniform,
                    Some(read_only) => wgpu::BufferBindingType::Storage { read_only },
                },
            )
        })
        .collect();
    let bind_layout =
        gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries });
    let layout = gpu.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(&bind_layout)],
        immediate_size: 0,
    });
    (bind_layout, layout)
}

fn entry(binding: u32, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    }
}

impl Pipelines {
    pub fn new(gpu: &Gpu) -> Pipelines {
        // shaders/prelude.wgsl: parameters, rays (read), hits (write), three scene buffers (read),
        // records (write); the kernel scratch (read and write): shaders/dispatch_persistent.wgsl's
        // item counter, shaders/wide_ray_stream.wgsl's lists.
        let (read, write) = (Some(true), Some(false));
        let (bind_layout, layout) =
            buffer_layout(gpu, "raytrail", &[None, read, write, read, read, read, write, write]);
        Pipelines { bind_layout, layout, compiled: Mutex::new(HashMap::new()) }
    }

    /// The kernel of `v`, compiled now if it was not yet.
    pub fn get(&self, gpu: &Gpu, v: &Variant) -> Result<Arc<wgpu::ComputePipeline>, Error> {
        if let Some(p) = self.compiled.lock().map_err(|_| poisoned())?.get(v) {
            return Ok(p.clone());
        }
        let label = v.label();
        let pipeline = gpu.compute_pipeline(&label, &v.source()?, &v.overrides(), &self.layout)?;
        let pipeline = Arc::new(pipeline);
        self.compiled.lock().map_err(|_| poisoned())?.insert(*v, pipeline.clone());
        Ok(pipeline)
    }
}

fn poisoned() -> Error {
    crate::device::device_error("the kernel cache was poisoned by a panic in another thread")
}
