//! Finding an adapter and opening a device with what the kernels need.

use raytrail_core::Error;
use std::sync::Arc;

/// Names the backend in errors.
pub(crate) const BACKEND: &str = "wgpu";

/// A device error with its detail.
pub(crate) fn device_error(detail: impl Into<String>) -> Error {
    Error::Device { backend: BACKEND, detail: detail.into() }
}

/// An open device: the queue, the adapter's description, and what it supports.
pub struct Gpu {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    pub(crate) info: wgpu::AdapterInfo,
    pub(crate) limits: wgpu::Limits,
    /// Whether compute passes can be timed with timestamp queries.
    pub(crate) timestamps: bool,
    /// Whether kernels are compiled to SPIR-V that asks the driver to keep subnormals (see
    /// [`crate::spirv`]); otherwise they go to wgpu as WGSL and the driver's default applies.
    pub(crate) preserve_subnormals: bool,
    /// Why the kernels have the form they have, for reports.
    pub(crate) form_reason: &'static str,
}

/// Environment variable choosing the [`KernelForm`] of [`crate::WgpuBackend::new`]: `auto` (the
/// default), `wgsl` or `spirv`.
pub const KERNEL_FORM: &str = "RAYTRAIL_WGPU_KERNELS";

/// How the kernels are handed to the driver.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum KernelForm {
    /// WGSL where its kernels already keep subnormals; else SPIR-V with `DenormPreserve` where the
    /// driver reports the mode or, not reporting it, is shown by the numerics probe to honour it
    /// (NVIDIA's Vulkan driver 580 does); else WGSL, and the conformance suite reports the flushes.
    #[default]
    Auto,
    /// WGSL through wgpu: the driver's default subnormal mode applies (to compare speed, or to see
    /// what that default does to conformance).
    Wgsl,
    /// SPIR-V with subnormals preserved wherever wgpu's passthrough is available, even where the
    /// driver does not report the mode (to test that path on drivers that keep subnormals anyway).
    Spirv,
}

impl KernelForm {
    /// The form named by [`KERNEL_FORM`] (`Auto` when unset); an unknown name is an error.
    pub fn from_env() -> Result<KernelForm, Error> {
        match std::env::var(KERNEL_FORM).as_deref() {
            Err(_) | Ok("") | Ok("auto") => Ok(KernelForm::Auto),
            Ok("wgsl") => Ok(KernelForm::Wgsl),
            Ok("spirv") => Ok(KernelForm::Spirv),
            Ok(other) => Err(device_error(format!("{KERNEL_FORM}={other}: expected auto, wgsl or spirv"))),
        }
    }
}

impl Gpu {
    /// Opens the first adapter wgpu finds (high-performance preference), with 64-bit floats (the
    /// watertight test's exact fallback), where supported timestamp queries, and kernels in `form`
    /// (for `Auto`, settled by the numerics probe where the driver does not report float controls).
    ///
    /// Fails with [`Error::Device`] naming the reason when there is no adapter, it lacks f64, or it
    /// cannot take the form asked for.
    pub fn open(form: KernelForm) -> Result<Gpu, Error> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle());
        let options = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            // The kernels are sized from the adapter's real limits.
            apply_limit_buckets: false,
        };
        let adapter = pollster::block_on(instance.request_adapter(&options))
            .map_err(|e| device_error(format!("no GPU adapter found ({e})")))?;
        let info = adapter.get_info();
        let available = adapter.features();
        if !available.contains(wgpu::Features::SHADER_F64) {
            return Err(device_error(format!(
                "adapter '{}' lacks 64-bit floats (SHADER_F64), which the watertight test's exact fallback needs",
                info.name
            )));
        }
        let mut features = wgpu::Features::SHADER_F64;
        let timestamps = available.contains(wgpu::Features::TIMESTAMP_QUERY);
        if timestamps {
            features |= wgpu::Features::TIMESTAMP_QUERY;
        }
        let passthrough = available.contains(wgpu::Features::PASSTHROUGH_SHADERS);
        let driver_denorm_preserve = crate::float_controls::driver_can_preserve_subnormals(&adapter);
        let (preserve_subnormals, form_reason) = match form {
            KernelForm::Auto if passthrough && driver_denorm_preserve == Some(true) => {
                (true, "the driver reports DenormPreserve for f32")
            }
            // Settled by the probe once the device is open.
            KernelForm::Auto => (false, "no shader passthrough"),
            KernelForm::Wgsl => (false, "asked for"),
            KernelForm::Spirv if passthrough => (true, "asked for"),
            KernelForm::Spirv => {
                return Err(device_error(format!(
                    "adapter '{}' cannot take SPIR-V kernels (no shader passthrough)",
                    info.name
                )))
            }
        };
        if passthrough && form != KernelForm::Wgsl {
            features |= wgpu::Features::PASSTHROUGH_SHADERS;
        }
        let limits = adapter.limits();
        let desc = wgpu::DeviceDescriptor {
            label: Some("raytrail"),
            required_features: features,
            required_limits: limits.clone(),
            ..Default::default()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&desc))
            .map_err(|e| device_error(format!("adapter '{}' refused a device: {e}", info.name)))?;
        // Errors are caught with error scopes where they can happen; anything else is logged
        // rather than aborting the process (wgpu's default handler panics).
        device.on_uncaptured_error(Arc::new(|e: wgpu::Error| eprintln!("raytrail-wgpu: uncaptured device error: {e}")));
        let mut gpu = Gpu { device, queue, info, limits, timestamps, preserve_subnormals, form_reason };
        if form == KernelForm::Auto && passthrough && driver_denorm_preserve != Some(true) {
            gpu.settle_kernel_form()?;
        }
        Ok(gpu)
    }

    /// The adapter's name, driver and API, for reports.
    pub fn describe(&self) -> String {
        format!(
            "{} ({}, {:?}; kernels as {})",
            self.info.name,
            self.info.driver_info,
            self.info.backend,
            self.kernel_form()
        )
    }

    /// How the kernels reach the driver, and why.
    pub fn kernel_form(&self) -> String {
        let form = if self.preserve_subnormals { "SPIR-V with DenormPreserve" } else { "WGSL" };
        format!("{form}: {}", self.form_reason)
    }

    /// Runs `f`, turning any validation or out-of-memory error it raises into [`Error::Device`].
    pub(crate) fn checked<R>(&self, what: &str, f: impl FnOnce() -> R) -> Result<R, Error> {
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let r = f();
        let v = pollster::block_on(validation.pop());
        let o = pollster::block_on(oom.pop());
        match v.or(o) {
            Some(e) => Err(device_error(format!("{what}: {e}"))),
            None => Ok(r),
        }
    }
}
