//! kd-trees and their traversals (Horn, Sugerman, Houston & Hanrahan 2007).
//!
//! - [`KdTree`]: nodes of 8 bytes ([`KdNode`]), siblings adjacent, leaves pointing into a
//!   primitive-reference array;
//! - [`KdBuilder`]: a SAH builder with triangles clipped to node bounds (needs `alloc`);
//! - [`traverse`]: the five traversals, one state machine each.

mod memory;
mod node;
pub mod traverse;
pub use memory::{KdMemory, KdSliceMemory};
pub use node::KdNode;

#[cfg(feature = "alloc")]
mod build;
#[cfg(feature = "alloc")]
mod tree;
#[cfg(feature = "alloc")]
pub use build::{KdBuilder, KdConfig};
#[cfg(feature = "alloc")]
pub use tree::{KdStats, KdTree};
