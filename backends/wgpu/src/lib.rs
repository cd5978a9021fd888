//! raytrail-wgpu: the wgpu backend of raytrail.
//!
//! [`WgpuBackend`] implements the backend-agnostic [`Trace`](raytrail_core::trace::Trace) trait
//! with WGSL compute kernels (one work item per ray; one per packet of four rays for kd-packet; a
//! pipeline of kernels for the stream method, whose stages are all on the device). Work items go
//! to invocations one each or by persistent threads ([`Dispatch`]); a long trace is a stream of
//! batches, several in flight, through buffers each scene keeps between calls ([`GpuConfig`]).
//! [`WgpuBackend::time_kernel`] times the kernels alone, at steady clocks. Kernels are
//! composed from the files in `shaders/` and specialized per method, key width, triangle test,
//! query and recording ([`compose`]). Each kernel mirrors its core state machine transition for
//! transition, and its arithmetic is written to come out bit for bit as on the CPU whatever the
//! shader compiler does (NUMERICS.md in this crate says how).
//!
//! Without an adapter, [`WgpuBackend::new`] returns an error naming why; callers (the CLI, the
//! conformance suite) then go on with the CPU backend.
#![warn(missing_docs)]

mod all_hits;
mod backend;
mod batch;
pub mod compose;
mod config;
mod device;
mod float_controls;
mod kernel;
mod launch;
mod nearest;
mod params;
mod pipelines;
mod probe;
mod record;
mod scene;
mod spirv;
mod stream;
mod timing;
mod wide_query;
mod workspace;

pub use backend::WgpuBackend;
pub use config::{
    Dispatch, GpuConfig, CPU_ADAPTER_ROUNDS, DEFAULT_BATCH_RAYS, DEFAULT_PERSISTENT_WORKGROUPS, MAX_PERSISTENT_ROUNDS,
};
pub use device::{KernelForm, KERNEL_FORM};
pub use probe::NumericsProbe;
pub use scene::WgpuScene;
pub use timing::{KernelTiming, TimingPlan};

/// Environment variable that turns a missing adapter from a skip into a failure (CI sets it).
pub const REQUIRE_GPU: &str = "RAYTRAIL_REQUIRE_GPU";
