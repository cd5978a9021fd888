//! The conformance suite on the wgpu backend: the same scenes, ray sets, methods and queries as
//! the CPU suite. On the GPU, every method must agree with its reference as on the CPU, and every
//! method's hits and enumerations must equal the CPU's ray by ray, bit for bit.
//!
//! Without an adapter each test prints a one-line SKIPPED reason and passes, unless
//! `RAYTRAIL_REQUIRE_GPU=1` (CI sets it, with Mesa's lavapipe installed), which makes it a failure.

mod common;

conformance_suite!(common::gpu::check_scene_gpu);
