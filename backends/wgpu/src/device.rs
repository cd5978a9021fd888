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
}

impl Gpu {
    /// Opens the first adapter wgpu finds (high-performance preference), with 64-bit floats (the
    /// watertight test's exact fallback) and, where supported, timestamp queries.
    ///
    /// Fails with [`Error::Device`] naming the reason when there is no adapter or it lacks f64.
    pub fn open() -> Result<Gpu, Error> {
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
        Ok(Gpu { device, queue, info, limits, timestamps })
    }

    /// The adapter's name, driver and API, for reports.
    pub fn describe(&self) -> String {
        format!("{} ({}, {:?})", self.info.name, self.info.driver_info, self.info.backend)
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
