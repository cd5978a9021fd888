//! Wide BVHs collapsed from the canonical binary tree, and their traversal (Guthe 2014).
//!
//! - [`WideNode`]: `W` child boxes as a structure of arrays, child references and leaf ranges,
//!   `Pod`, one byte layout for the CPU and the WGSL kernels;
//! - [`WideBvh`]: the collapse (Guthe's pull-up, or every second level removed), keeping every
//!   binary leaf whole (needs `alloc`), and refitted with it after the vertices move ([`WideBvh::refit`]);
//! - [`ChildKernel`]: testing and ordering a node's children, by the plain [`ReferenceKernel`] or
//!   the [`FastKernel`] (SIMD box tests, the sorting network of [`network`]) that must equal it;
//! - [`LeafBlock`]: four of a leaf's triangles and their primitive ids, as the CPU reads them;
//! - [`WideMemory`]: what a traversal reads, in plain slices or with the hit children
//!   prefetched ([`PrefetchingMemory`], for trees larger than the caches);
//! - [`traverse`]: the state machine;
//! - [`trail`]: the same order without a stack, by node keys, a bit trail and a perfect hash over
//!   the keys ([`keyed`]);
//! - [`packet`]: the same tree walked by packets of rays of one octant (one order and one stack
//!   per packet, each ray's own box tests, answers and events);
//! - [`ray_stream`]: the same tree walked by streams of thousands of rays (one order and one
//!   stack per stream, each ray's own box tests, answers and events, no hand-over).

mod kernel;
pub mod keyed;
mod leaf_block;
mod memory;
pub mod network;
mod node;
#[cfg(feature = "alloc")]
mod optimal;
pub mod packet;
mod prefetch;
#[cfg(feature = "alloc")]
pub mod ray_stream;
#[cfg(feature = "alloc")]
mod refit;
pub mod trail;
pub mod traverse;
#[cfg(feature = "alloc")]
mod tree;

pub use kernel::{sort_keys, ChildHits, ChildKernel, FastKernel, ReferenceKernel, StreamRay};
pub use leaf_block::LeafBlock;
pub use memory::{WideMemory, WideSliceMemory};
pub use node::{WideChild, WideNode, EMPTY_CHILD};
pub use prefetch::{worth_prefetching, PrefetchingMemory, PREFETCH_ABOVE_BYTES};
#[cfg(feature = "alloc")]
pub use tree::{WideBvh, WideStats, WideTree};

/// Rays per stream of [`ray_stream`] (consecutive rays of a batch, from its start): part of the
/// rule, since a ray's events depend on the stream it is traced in. Streams of 2048-4096 rays
/// measured best; at 16,384 the rays' records and lists outgrow a 1 MB L2 and the stream lost
/// (`docs/notes/*-benchmarks-bvh8-stream.md`, "A ray-stream prototype").
pub const STREAM_RAYS: usize = 4096;

/// Rays per wide packet of [`packet`]: four registers of eight lanes on AVX2, and where packets
/// measured best against single rays on coherent rays (the prototype's 8 to 64 rays:
/// `docs/notes/*-benchmarks-ci-and-single-ray.md`, "Single-ray changes that did not pay").
pub const WIDE_PACKET: usize = 32;
