//! BVH2 traversal state machines, all visiting nodes in the same order (closer child first, ties
//! to the left), so their enumerations are comparable node for node:
//! - [`StackState`]: a stack, the "while-while" order of Aila & Laine (2009) (method a);
//! - [`ParentSiblingState`]: parent and sibling links and a bit trail, Áfra et al. 2014 (b);
//! - [`RegisterState`] with [`UncleHops`]: the most-recently-postponed-node register, uncle links
//!   and iterative two-level hops (c);
//! - [`RegisterState`] with [`PerfectHashLookup`]: constant-time backtracking, Binder & Keller
//!   2016, Algorithm 1 (d), optionally with the disjoint t-interval mask (e);
//! - [`PausingState`]: method (d) pausing after a hit and resuming from a node key ([`Paused`])
//!   (f).
//!
//! Each is a [`Machine`](crate::traverse::Machine) and reads memory only through
//! [`BvhMemory`](super::BvhMemory). The same code is the CPU
//! backend's hot loop, the hardware simulator's lockstep unit and the reference each shader
//! mirrors. [`trace_batch`] and [`trace_ray`] take a [`Bvh2Method`](crate::method::Bvh2Method), so
//! a method of another structure cannot reach them:
//!
//! ```compile_fail
//! use raytrail_core::bvh2::traverse::trace_ray;
//! use raytrail_core::method::KdMethod;
//! # fn f(mem: &raytrail_core::bvh2::SliceMemory<'_>, root: raytrail_core::bvh2::traverse::TraceRoot, ray: &raytrail_core::Ray) {
//! let mut obs = raytrail_core::observe::NoObserver;
//! // A kd method handed to a BVH2 traversal does not compile.
//! trace_ray::<u32, _, raytrail_core::intersect::Watertight, _>(
//!     KdMethod::Stack, mem, root, ray, raytrail_core::method::Query::Closest, &mut obs);
//! # }
//! ```

mod children;
mod leaf;
mod parent_sibling;
mod register;
mod resume;
mod run;
mod stack;

pub use children::{order_children, Descent};
pub use leaf::intersect_leaf;
pub use parent_sibling::ParentSiblingState;
pub use register::{Fallback, PerfectHashLookup, RegisterState, UncleHops};
pub use resume::{Paused, PausingState};
pub use run::{trace_batch, trace_ray, TraceRoot};
pub use stack::StackState;
