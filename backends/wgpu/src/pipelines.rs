//! Kernels compiled on first use and kept: one per [`Variant`] a caller asks for, and one per
//! distinct kernel text. Methods that differ only in the tree they walk (`bvh8` and `bvh8-sah`,
//! say) compose the same WGSL with the same overrides; they share one compiled kernel, since a
//! compile is the fixed cost of a device (seconds a kernel on a CPU Vulkan driver).

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
    by_text: Mutex<HashMap<KernelText, Arc<wgpu::ComputePipeline>>>,
}

/// What a compiled kernel is made from: its WGSL and its override values (as bits, so they hash).
#[derive(PartialEq, Eq, Hash)]
struct KernelText {
    source: String,
    overrides: Vec<(&'static str, u64)>,
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
        // records (write); the kernel scratch (read and write): shaders/loop_guard.wgsl's dispatch
        // state (the persistent item counter, the loop guard's flag), shaders/wide_ray_stream.wgsl's
        // lists.
        let (read, write) = (Some(true), Some(false));
        let (bind_layout, layout) =
            buffer_layout(gpu, "raytrail", &[None, read, write, read, read, read, write, write]);
        Pipelines { bind_layout, layout, compiled: Mutex::new(HashMap::new()), by_text: Mutex::new(HashMap::new()) }
    }

    /// The kernel of `v`, compiled now if it was not yet.
    pub fn get(&self, gpu: &Gpu, v: &Variant) -> Result<Arc<wgpu::ComputePipeline>, Error> {
        if let Some(p) = self.compiled.lock().map_err(|_| poisoned())?.get(v) {
            return Ok(p.clone());
        }
        let overrides = v.overrides();
        let text = KernelText {
            source: v.source()?,
            overrides: overrides.iter().map(|&(name, value)| (name, value.to_bits())).collect(),
        };
        let known = self.by_text.lock().map_err(|_| poisoned())?.get(&text).cloned();
        let pipeline = match known {
            Some(p) => p,
            None => {
                let p = Arc::new(gpu.compute_pipeline(&v.label(), &text.source, &overrides, &self.layout)?);
                self.by_text.lock().map_err(|_| poisoned())?.insert(text, p.clone());
                p
            }
        };
        self.compiled.lock().map_err(|_| poisoned())?.insert(*v, pipeline.clone());
        Ok(pipeline)
    }
}

fn poisoned() -> Error {
    crate::device::device_error("the kernel cache was poisoned by a panic in another thread")
}
