//! Instancing: meshes placed many times by affine transforms, traced through a top-level BVH
//! over the placements' world boxes.
//!
//! - [`Transform`]: a 3x4 affine map from a mesh's frame to the world; rays go the other way,
//!   keeping their `t`.
//! - [`Instance`]: a mesh index, a transform, an id for its hits and a 32-bit mask.
//! - [`InstancedScene`]: the instances with each mesh prepared once by a backend, and the
//!   top-level BVH (the binned SAH builder over the world boxes).
//! - [`trace_instanced`]: closest or any hits through any backend and method, in waves of
//!   per-instance batches; [`InstanceHit`] carries the instance's id.
//!
//! Instanced answers are not bit-identical to those of the same triangles flattened into one
//! mesh: the flattened vertices and the mapped rays round differently. Both agree with the exact
//! answer of the flattened triangles within the conformance suite's edge tolerance, which is how
//! the suite checks them.

mod hit;
mod scene;
mod trace;
mod transform;

pub use hit::InstanceHit;
pub use scene::{Instance, InstancedScene};
pub use trace::{trace_instanced, InstancedReport};
pub use transform::Transform;
