//! raytrail: ray-traversal methods for triangle scenes, checked against each other.
//!
//! Load a mesh, build its tree, prepare it for the methods you will use, and trace:
//!
//! ```
//! use raytrail::prelude::*;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! // A mesh (here a triangle as OBJ text; `load_scene("file.obj")` reads a file).
//! let mesh = raytrail::core::mesh::load_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "tri.obj")?;
//! let scene = mesh.to_scene()?;
//! // The canonical tree, and what the chosen method needs of it (here, the perfect hash).
//! let bvh = Builder::Sah.build(&scene)?;
//! let method = Method::Bvh2(Bvh2Method::Hash);
//! let prepared = Arc::new(PreparedScene::new(&scene, bvh, &[method])?);
//! // A backend prepares the scene once and traces batches of rays.
//! let backend = CpuBackend::new();
//! let cpu_scene = backend.prepare(prepared)?;
//! let rays = [Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::new(0.0, 0.0, -1.0), 0.0, f32::INFINITY)];
//! let mut hits = [Hit::MISS];
//! backend.trace(&cpu_scene, &rays, &TraceOptions::new(method), &mut hits)?;
//! assert_eq!(hits[0].prim, 0);
//! assert_eq!(hits[0].t, 1.0);
//! # Ok(())
//! # }
//! ```
//!
//! The crates behind it:
//! - [`core`]: the `no_std` core (types, tests, keys, layouts, perfect hashing, state machines);
//! - [`cpu`]: the rayon backend and the obvhs (PLOC) builder;
//! - [`gpu`]: the wgpu backend (WGSL kernels mirroring the core's state machines);
//! - [`conformance`]: the scenes, ray sets, checks and the suite every backend runs.
//!
//! The command line (`raytrail`, the bench and NumPy files) is the `raytrail-cli` package, so this
//! library pulls in no bench dependency. docs/ARCHITECTURE.md tells how the parts fit.
#![warn(missing_docs)]

pub mod analysis;
mod builder;
pub mod prelude;

pub use raytrail_conformance as conformance;
pub use raytrail_core as core;
pub use raytrail_cpu as cpu;
pub use raytrail_wgpu as gpu;

pub use builder::Builder;

use raytrail_conformance::NamedScene;
use raytrail_core::mesh::{LoadOptions, LoadReport};
use std::path::Path;

/// Name of the built-in scene.
pub const BUILTIN_SCENE: &str = "builtin";

/// Loads a mesh file, or the built-in generated scene for [`BUILTIN_SCENE`], with the default
/// loading policy (elements that are not triangles or polygons skipped; see
/// [`raytrail_core::mesh`]).
pub fn load_scene(path: &str) -> Result<NamedScene, String> {
    load_scene_with(path, &LoadOptions::default()).map(|(scene, _)| scene)
}

/// Loads a mesh file, or the built-in generated scene for [`BUILTIN_SCENE`], with the given
/// loading policy; also returns what loading skipped and, with [`LoadOptions::sources`], where
/// each triangle came from (the built-in scene's report is empty).
pub fn load_scene_with(path: &str, options: &LoadOptions) -> Result<(NamedScene, LoadReport), String> {
    if path == BUILTIN_SCENE {
        return raytrail_conformance::generated()
            .into_iter()
            .find(|s| s.name == "sphereflake")
            .map(|s| (s, LoadReport::default()))
            .ok_or_else(|| "the built-in sphereflake scene is missing".to_string());
    }
    let (mesh, report) = raytrail_core::mesh::load_with(Path::new(path), options).map_err(|e| e.to_string())?;
    let scene = mesh.to_scene().map_err(|e| match report.skipped {
        0 => format!("{path}: {e}"),
        1 => format!("{path}: {e} (1 element that is not a triangle or polygon was skipped)"),
        n => format!("{path}: {e} ({n} elements that are not triangles or polygons were skipped)"),
    })?;
    let name = Path::new(path).file_name().map_or(path.to_string(), |n| n.to_string_lossy().into_owned());
    Ok((NamedScene::new(name, scene), report))
}
