//! Compiling a compute kernel: WGSL through wgpu, or SPIR-V with subnormals preserved where the
//! adapter can keep them ([`crate::spirv`]).

use crate::device::Gpu;
use raytrail_core::Error;
use std::borrow::Cow;

/// Samples of the probe that settles the kernel form: enough to include the special cases and a
/// few dozen subnormal products, a fraction of a millisecond on a GPU.
const SETTLE_SAMPLES: usize = 1 << 13;

impl Gpu {
    /// Picks the kernel form by measurement, for drivers that do not report `DenormPreserve`: WGSL
    /// if its arithmetic matches the CPU (lavapipe); else SPIR-V with `DenormPreserve` if that
    /// matches (NVIDIA's Vulkan driver 580 honours the mode without reporting it); else WGSL, and
    /// the flushes show in the probe and the conformance suite.
    pub(crate) fn settle_kernel_form(&mut self) -> Result<(), Error> {
        self.preserve_subnormals = false;
        if crate::probe::probe(self, SETTLE_SAMPLES)?.kernels_exact() {
            self.form_reason = "its kernels keep subnormals as they are";
            return Ok(());
        }
        self.preserve_subnormals = true;
        // A driver that rejects the mode fails the compile: that, too, means WGSL.
        if crate::probe::probe(self, SETTLE_SAMPLES).is_ok_and(|p| p.kernels_exact()) {
            self.form_reason =
                "WGSL kernels flush subnormals; the mode, not reported by the driver, is honoured (probed)";
            return Ok(());
        }
        self.preserve_subnormals = false;
        self.form_reason = "WGSL kernels flush subnormals, and DenormPreserve does not help (probed)";
        Ok(())
    }

    /// The compute pipeline of the WGSL `source` (entry point `main`) with `overrides`, over
    /// `layout`. Compilation and validation errors come back as [`Error::Device`] naming `label`.
    pub(crate) fn compute_pipeline(
        &self,
        label: &str,
        source: &str,
        overrides: &[(&str, f64)],
        layout: &wgpu::PipelineLayout,
    ) -> Result<wgpu::ComputePipeline, Error> {
        let what = format!("compiling kernel {label}");
        if !self.preserve_subnormals {
            return self.checked(&what, || {
                let module = self.device.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(label),
                    source: wgpu::ShaderSource::Wgsl(source.into()),
                });
                self.pipeline(label, &module, overrides, layout)
            });
        }
        let words = crate::spirv::compile_preserving_subnormals(source, overrides)
            .map_err(|e| crate::device::device_error(format!("{what}: {e}")))?;
        self.checked(&what, || {
            let desc = wgpu::ShaderModuleDescriptorPassthrough {
                label: Some(label),
                // The workgroup size is read from the module on Vulkan; Metal alone needs it here.
                entry_points: Cow::Owned(vec![wgpu::PassthroughShaderEntryPoint {
                    name: "main".into(),
                    workgroup_size: (0, 0, 0),
                }]),
                spirv: Some(Cow::Owned(words)),
                ..Default::default()
            };
            // SAFETY: the module is naga's own output for a WGSL source naga validated, with
            // overrides resolved and index bounds checks in (buffer accesses rely on robust
            // buffer access, which wgpu enables on every Vulkan device, as wgpu's own modules
            // do), plus the DenormPreserve mode: reported by the driver, asked for, or being
            // probed (`settle_kernel_form`).
            let module = unsafe { self.device.create_shader_module_passthrough(desc) };
            self.pipeline(label, &module, &[], layout)
        })
    }

    fn pipeline(
        &self,
        label: &str,
        module: &wgpu::ShaderModule,
        overrides: &[(&str, f64)],
        layout: &wgpu::PipelineLayout,
    ) -> wgpu::ComputePipeline {
        self.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            module,
            entry_point: Some("main"),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: overrides,
                zero_initialize_workgroup_memory: false,
            },
            cache: None,
        })
    }
}
