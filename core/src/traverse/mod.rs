//! What every traversal shares, whatever structure it walks: the per-ray prelude ([`begin`]), the
//! answer being built ([`QueryState`]) and what a step leaves to do ([`Step`]).
//!
//! Every per-ray method is a [`Machine`]: a small state (exactly the registers its paper names)
//! and a `step` that makes one transition, reading memory only through its structure's memory
//! trait and reporting events to an [`Observer`](crate::observe::Observer); [`drive`] is the one
//! budgeted loop over it. The states live with their structure: [`crate::bvh2::traverse`],
//! [`crate::kd::traverse`] and [`crate::wide`].

mod begin;
mod machine;
pub mod packets;
mod query;

pub use crate::method::Query;
pub use begin::{begin, begin_slab, for_each_ray};
pub use machine::{drive, Machine};
pub use query::QueryState;

/// What a step leaves to do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// More nodes to process.
    Continue,
    /// A leaf accepted a hit and traversal continues: the natural point to pause (Sec. 2.4).
    AfterHit,
    /// Traversal is over.
    Done,
}
