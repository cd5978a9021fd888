//! The ray-stream method of Garanzha & Loop (2010): rays hashed and sorted into coherent packets,
//! a frustum per packet, breadth-first frustum traversal of an 8-wide BVH stored level by level,
//! and localized intersection of each packet with the leaves its frustum reached.
//!
//! - [`ray_hash`]: the 32-bit key of a ray (origin and direction on two virtual grids);
//! - [`scan`], [`sort`]: the parallel primitives and the compression-sorting-decompression
//!   scheme, with the packet decomposition;
//! - [`frustum`]: packet frustums and the frustum-box test;
//! - [`levels`]: the level-order 8-wide tree;
//! - [`traverse`]: the breadth-first traversal;
//! - [`localized`]: the intersection stage;
//! - [`pipeline`]: the stages end to end, over a [`Parallel`] executor.
//!
//! docs/ARCHITECTURE.md, "The ray-stream method", says where and why this departs from the paper.

pub mod exec;
pub mod frustum;
pub mod levels;
pub mod localized;
mod params;
pub mod pipeline;
pub mod ray_hash;
pub mod scan;
pub mod sort;
pub mod traverse;

pub use exec::{Parallel, Serial};
pub use frustum::{Frustum, FrustumCull, FrustumTest};
pub use levels::{LevelBvh, LevelNode};
pub use params::{StreamParams, MAX_PACKET};
pub use pipeline::{trace_stream, trace_stream_with, StageSeconds, StreamOutput, StreamPlan, StreamScene, StreamStats};
