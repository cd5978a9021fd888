//! The conformance suite on the wgpu backend configured the other way from conformance.rs: kernels
//! as SPIR-V with `DenormPreserve` (the form NVIDIA's driver gets), streams of small batches (about
//! a thousand rays, three in flight, so every ray set is several batches) and persistent threads
//! in workgroups of 32 (four resident workgroups fetching from the counter). Each method's hits
//! and enumerations must equal the serial reference backend's, bit for bit.
//!
//! The cases that reach every kernel, both key widths and each tree builder once (generated
//! scenes, the small meshes): conformance.rs runs every kernel on the large meshes and on every
//! tree of the generated scenes already, and on lavapipe a rerun of those here was the suite's
//! largest cost in CI. An adapter that cannot take SPIR-V runs the WGSL
//! kernels instead, with a line saying so, unless `RAYTRAIL_REQUIRE_GPU=1`, which makes that a
//! failure.
//!
//! Without an adapter each test prints a one-line SKIPPED reason and passes, unless
//! `RAYTRAIL_REQUIRE_GPU=1`.

use raytrail_conformance::suite::REQUIRE_GPU;
use raytrail_wgpu::{Dispatch, GpuConfig, KernelForm, WgpuBackend};

fn spirv_streamed_persistent() -> Result<WgpuBackend, raytrail_core::Error> {
    let config = GpuConfig {
        batch_rays: 1000,
        in_flight: 3,
        dispatch: Dispatch::Persistent { workgroups: 4 },
        workgroup_size: 32,
    };
    let backend = match WgpuBackend::with_kernel_form(KernelForm::Spirv) {
        Ok(backend) => backend,
        Err(e) if std::env::var(REQUIRE_GPU).as_deref() != Ok("1") => {
            eprintln!("SKIPPED SPIR-V kernels: {e}; the WGSL kernels run instead");
            WgpuBackend::new()?
        }
        Err(e) => return Err(e),
    };
    backend.configured(config)
}

raytrail_conformance::conformance_suite!(small: try spirv_streamed_persistent());
