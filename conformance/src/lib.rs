//! raytrail-conformance: the scenes, ray sets and checks that every backend and method must pass.
//!
//! The contract (DESIGN.md, "Conformance"): on every scene and ray set, every method returns the
//! stack method's hits (primitive id and `t` bit for bit; any hit: occluded or not), and every
//! method enumerates exactly the nodes its reference method does ([`Method::reference`]). Each
//! backend runs the same checks ([`check::check_ray_set`]) through the
//! [`Trace`](raytrail_core::trace::Trace) trait.
//!
//! [`Method::reference`]: raytrail_core::traverse::Method::reference
#![warn(missing_docs)]

pub mod check;
pub mod paths;
pub mod rays;
pub mod rng;
pub mod scenes;

pub use check::{check_ray_set, compare, Context, Difference, Mismatch};
pub use paths::{load_mesh_scene, scenes_dir, MESH_FILES};
pub use rays::{ray_sets, RaySet, RaySetKind, RaySetSize};
pub use scenes::{generated, NamedScene};
