//! The stream method (Garanzha & Loop 2010; `raytrail_core::stream`) on the device, every stage a
//! compute kernel: ray keys, compression, radix sort and decompression, packet decomposition,
//! frustums, the breadth-first traversal, localized intersection. Every intermediate array is
//! the core's, bit for bit (tests/stream_stages.rs checks them against the serial pipeline); the
//! host only reads counts back to size the next arrays.

pub(crate) mod compose;
pub(crate) mod kernels;
mod plan;
mod run;
mod scan;
pub(crate) mod shared_parts;
mod sort;
mod trace;
mod traverse;

pub(crate) use trace::{plan_only, trace};
