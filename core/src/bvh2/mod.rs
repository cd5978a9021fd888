//! Binary bounding volume hierarchies: the canonical tree, its builders and its node layouts.
//!
//! - [`Bvh2`]: the canonical tree, the single source of truth (node identity = index, pre-order).
//! - [`Bvh2::refit`]: new boxes for moved triangles, the topology (and every table made from it)
//!   kept.
//! - [`SahBuilder`]: a binned SAH builder (needs `alloc`); [`SahConfig::tree_cost`] prices a
//!   finished tree, whoever built it.
//! - [`SbvhBuilder`]: the same with spatial splits (Stich et al. 2009): a triangle cut by a
//!   split plane is referenced from a leaf on each side.
//! - [`BinaryLayout`]: the Aila-Laine layout (both child boxes in the parent, leaf triangle arrays
//!   closed by a termination marker) with uncle or parent/sibling links in the padding.
//! - [`BvhMemory`]: the narrow read interface traversals use.
//! - [`traverse`]: the traversal state machines (methods a-f).

mod memory;
mod node;
pub mod traverse;
pub use memory::{BvhMemory, MemRead, SliceMemory};
pub use node::{BinaryNode, LeafWord, NodeRef};

#[cfg(feature = "alloc")]
mod cost;
#[cfg(feature = "alloc")]
mod layout;
#[cfg(feature = "alloc")]
pub(crate) mod refit;
#[cfg(feature = "alloc")]
mod sah;
#[cfg(feature = "alloc")]
mod sbvh;
#[cfg(feature = "alloc")]
mod tree;
#[cfg(feature = "alloc")]
pub use layout::{BinaryLayout, LinkKind};
#[cfg(feature = "alloc")]
pub use sah::{SahBuilder, SahConfig};
#[cfg(feature = "alloc")]
pub use sbvh::{SbvhBuilder, SbvhConfig};
#[cfg(feature = "alloc")]
pub use tree::{Bvh2, Bvh2Node, NodeKind, TreeStats};
