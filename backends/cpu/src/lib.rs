//! raytrail-cpu: the rayon CPU backend of raytrail.
//!
//! [`CpuBackend`] implements the backend-agnostic [`Trace`](raytrail_core::trace::Trace) trait:
//! rays are split into chunks traced in parallel, each chunk through the core's state machines
//! monomorphized for the tree's key width, the triangle test and what is recorded, so the fast
//! path carries no observer at all.
#![warn(missing_docs)]

mod all_hits;
mod backend;
mod bvh2;
mod chunk;
mod kd;
mod nearest;
mod record;
mod refit;
mod stream;
#[cfg(all(test, target_arch = "x86_64"))]
mod test_rng;
mod trace_order;
mod trail;
mod wide;
#[cfg(target_arch = "x86_64")]
mod x86;

pub use backend::{CpuBackend, CpuScene};
/// Why [`CpuBackend::with_threads`] could not make its pool (rayon's error).
pub use rayon::ThreadPoolBuildError;
