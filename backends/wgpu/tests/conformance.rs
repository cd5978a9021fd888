//! The conformance suite on the wgpu backend, one invocation per ray (the grid): the same cases
//! as every backend's; each method's hits and enumerations must equal the serial reference
//! backend's ray by ray, bit for bit. The default dispatch gives some methods persistent threads
//! instead (`Dispatch::ByMethod`); conformance_persistent.rs runs every method that way, with
//! the kernels as SPIR-V, on the cases that reach every kernel, so the two suites together cover
//! both dispatches and both kernel forms of every kernel.
//!
//! Without an adapter each test prints a one-line SKIPPED reason and passes, unless
//! `RAYTRAIL_REQUIRE_GPU=1` (CI sets it, with Mesa's lavapipe installed), which makes it a failure.

use raytrail_wgpu::{Dispatch, GpuConfig, WgpuBackend};

fn on_the_grid() -> Result<WgpuBackend, raytrail_core::Error> {
    WgpuBackend::new()?.configured(GpuConfig { dispatch: Dispatch::Grid, ..GpuConfig::default() })
}

raytrail_conformance::conformance_suite!(try on_the_grid());
