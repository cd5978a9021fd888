//! The conformance suite on the wgpu backend: the same cases as every backend's; each method's
//! hits and enumerations must equal the serial reference backend's ray by ray, bit for bit.
//!
//! Without an adapter each test prints a one-line SKIPPED reason and passes, unless
//! `RAYTRAIL_REQUIRE_GPU=1` (CI sets it, with Mesa's lavapipe installed), which makes it a failure.

raytrail_conformance::conformance_suite!(try raytrail_wgpu::WgpuBackend::new());
