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

pub(crate) fn entry(binding: u32, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    }
}

impl Pipelines {
    pub fn new(gpu: &Gpu) -> Pipelines {
        let read = wgpu::BufferBindingType::Storage { read_only: true };
        let write = wgpu::BufferBindingType::Storage { read_only: false };
        let entries = [
            entry(0, wgpu::BufferBindingType::Uniform),
            entry(1, read),
            entry(2, write),
            entry(3, read),
            entry(4, read),
            entry(5, read),
            entry(6, write),
        ];
        let bind_layout = gpu
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("raytrail"), entries: &entries });
        let layout = gpu.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("raytrail"),
            bind_group_layouts: &[Some(&bind_layout)],
            immediate_size: 0,
        });
        Pipelines { bind_layout, layout, compiled: Mutex::new(HashMap::new()) }
    }

    /// The kernel of `v`, compiled now if it was not yet.
    pub fn get(&self, gpu: &Gpu, v: &Variant) -> Result<Arc<wgpu::ComputePipeline>, Error> {
        if let Some(p) = self.compiled.lock().map_err(|_| poisoned())?.get(v) {
            return Ok(p.clone());
        }
        let label = v.label();
        let pipeline = gpu.compute_pipeline(&label, &v.source(), &v.overrides(), &self.layout)?;
        let pipeline = Arc::new(pipeline);
        self.compiled.lock().map_err(|_| poisoned())?.insert(*v, pipeline.clone());
        Ok(pipeline)
    }
}

fn poisoned() -> Error {
    crate::device::device_error("the kernel cache was poisoned by a panic in another thread")
}
