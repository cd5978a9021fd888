//! The conformance suite on the wgpu backend spread over the device the other way: streams of
//! small batches (about a thousand rays, three in flight, so every ray set is several batches) and
//! persistent threads in workgroups of 32 (four resident workgroups fetching from the counter).
//! Each method's hits and enumerations must equal the serial reference backend's, bit for bit.
//!
//! Without an adapter each test prints a one-line SKIPPED reason and passes, unless
//! `RAYTRAIL_REQUIRE_GPU=1`.

use raytrail_wgpu::{Dispatch, GpuConfig, WgpuBackend};

fn streamed_persistent() -> Result<WgpuBackend, raytrail_core::Error> {
    let config = GpuConfig {
        batch_rays: 1000,
        in_flight: 3,
        dispatch: Dispatch::Persistent { workgroups: 4 },
        workgroup_size: 32,
    };
    WgpuBackend::new()?.configured(config)
}

raytrail_conformance::conformance_suite!(try streamed_persistent());
