//! The stress suite (issue 15) on the wgpu backend: every method against the exact reference.
//! Without an adapter it prints a SKIPPED reason, unless `RAYTRAIL_REQUIRE_GPU=1`.

raytrail_conformance::stress_suite!(try raytrail_wgpu::WgpuBackend::new());
