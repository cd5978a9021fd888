//! Traversal state machines (DESIGN.md, "Traversal = state machine").
//!
//! Each method is a small per-ray state (exactly the registers its paper names) and a `step`
//! that makes one transition: it processes one node (an internal node's two child boxes, or a
//! leaf's triangles) and, where that ends a path, the backtracking step that finds the next node.
//! All memory reads go through [`BvhMemory`](crate::bvh2::BvhMemory); all events go to an
//! [`Observer`](crate::observe::Observer). The same code is the CPU backend's hot loop, the
//! hardware simulator's lockstep unit and the reference each shader mirrors.
//!
//! BVH2 methods, all visiting nodes in the same order (closer child first, ties to the left):
//! - [`StackState`]: a stack, the "while-while" order of Aila & Laine (2009) (method a);
//! - [`ParentSiblingState`]: parent and sibling links and a bit trail, Áfra et al. 2014 (b);
//! - [`RegisterState`] with [`UncleHops`]: the most-recently-postponed-node register, uncle links
//!   and iterative two-level hops (c);
//! - [`RegisterState`] with [`PerfectHashLookup`]: constant-time backtracking, Binder & Keller
//!   2016, Algorithm 1 (d), optionally with the disjoint t-interval mask (e);
//! - [`Paused`]: pausing after a hit and resuming from a node key (f).

mod children;
mod leaf;
mod method;
mod parent_sibling;
mod query;
mod register;
mod resume;
mod run;
mod stack;

pub use children::{order_children, Descent};
pub use leaf::intersect_leaf;
pub use method::{Family, Method, Query};
pub use parent_sibling::ParentSiblingState;
pub use query::QueryState;
pub use register::{Fallback, PerfectHashLookup, RegisterState, UncleHops};
pub use resume::{trace_pausing, Paused};
pub use run::{begin, begin_slab, trace_batch, trace_ray, TraceRoot};
pub use stack::StackState;

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
