//! raytrail: ray-traversal methods for triangle scenes.
//!
//! This package gathers the crates and ships the `raytrail` command line:
//! - [`core`]: the `no_std` core (types, tests, keys, layouts, perfect hashing, state machines);
//! - [`cpu`]: the rayon backend, the obvhs (PLOC) builder and NumPy files;
//! - [`gpu`]: the wgpu backend (WGSL kernels mirroring the core's state machines);
//! - [`conformance`]: the scenes, ray sets and cross-method checks.
#![warn(missing_docs)]

pub use raytrail_conformance as conformance;
pub use raytrail_core as core;
pub use raytrail_cpu as cpu;
pub use raytrail_wgpu as gpu;

use raytrail_conformance::NamedScene;
use raytrail_core::bvh2::{Bvh2, SahBuilder};
use raytrail_core::scene::Scene;
use std::path::Path;

/// Which builder makes the canonical tree.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Builder {
    /// The core's binned SAH builder.
    #[default]
    Sah,
    /// obvhs's PLOC with reinsertion.
    Ploc,
}

impl Builder {
    /// The builder of a command-line name.
    pub fn from_name(name: &str) -> Result<Builder, String> {
        match name {
            "sah" => Ok(Builder::Sah),
            "ploc" => Ok(Builder::Ploc),
            other => Err(format!("unknown builder '{other}' (known: sah, ploc)")),
        }
    }

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Builder::Sah => "sah",
            Builder::Ploc => "ploc",
        }
    }

    /// Builds the canonical tree of `scene`.
    pub fn build(self, scene: &Scene) -> Result<Bvh2, raytrail_core::Error> {
        match self {
            Builder::Sah => SahBuilder::default().build(scene.triangles()),
            Builder::Ploc => raytrail_cpu::ploc::build_ploc(scene.triangles(), 63),
        }
    }
}

/// Name of the built-in scene.
pub const BUILTIN_SCENE: &str = "builtin";

/// Loads a mesh file, or the built-in generated scene for [`BUILTIN_SCENE`].
pub fn load_scene(path: &str) -> Result<NamedScene, String> {
    if path == BUILTIN_SCENE {
        return raytrail_conformance::generated()
            .into_iter()
            .find(|s| s.name == "sphereflake")
            .ok_or_else(|| "the built-in sphereflake scene is missing".to_string());
    }
    let mesh = raytrail_core::mesh::load(Path::new(path)).map_err(|e| e.to_string())?;
    let scene = mesh.to_scene().map_err(|e| format!("{path}: {e}"))?;
    let name = Path::new(path).file_name().map_or(path.to_string(), |n| n.to_string_lossy().into_owned());
    Ok(NamedScene::new(name, scene))
}
