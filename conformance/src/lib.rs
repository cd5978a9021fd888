//! raytrail-conformance: the scenes, ray sets and checks that every backend and method must pass.
//!
//! The contract (docs/ARCHITECTURE.md, "Conformance"): on every scene and ray set, every method
//! returns the stack method's hits (primitive id and `t` bit for bit; any hit: occluded or not),
//! every method enumerates exactly the nodes its reference method does ([`Method::reference`]),
//! and every backend answers ray by ray as the [`SerialBackend`] does. A backend runs the whole
//! suite through the [`Trace`](raytrail_core::trace::Trace) trait with one line in a test file:
//!
//! ```ignore
//! raytrail_conformance::conformance_suite!(raytrail_cpu::CpuBackend::new());
//! ```
//!
//! [`Method::reference`]: raytrail_core::method::Method::reference
#![warn(missing_docs)]

pub mod all_hits;
pub mod check;
pub mod exact;
pub mod instanced;
pub mod nearest;
pub mod paths;
pub mod rays;
pub mod reference;
pub mod rng;
pub mod scenes;
pub mod stress;
pub mod suite;

pub use check::{check_ray_set, compare, Context, Difference, Mismatch};
pub use paths::{find_mesh, load_mesh_scene, scenes_dir, SceneFileError, MESH_FILES};
pub use rays::{ray_sets, RaySet, RaySetKind, RaySetSize};
pub use reference::SerialBackend;
pub use scenes::{generated, NamedScene};
pub use suite::Case;
