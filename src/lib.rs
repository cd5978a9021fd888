//! raytrail: ray-traversal methods for triangle scenes, implemented from their papers and checked
//! against each other.
//!
//! # Tracing in three lines
//!
//! ```
//! use raytrail::{Ray, Tracer, Vec3};
//! # fn main() -> Result<(), raytrail::Error> {
//! let tracer = Tracer::new(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]])?;
//! let ray = Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::new(0.0, 0.0, -1.0), 0.0, f32::INFINITY);
//! let hit = tracer.intersect_one(&ray)?.expect("the ray meets the triangle");
//! assert_eq!((hit.prim, hit.t), (0, 1.0));
//! # Ok(())
//! # }
//! ```
//!
//! [`Tracer`] takes triangles from memory (or a loaded mesh: [`load`]), builds the best tree
//! and traces batches ([`Tracer::intersect`], [`Tracer::occluded`], and `_into` forms that fill a
//! caller's slice) on all cores, picking for each large batch the fastest walk of its 8-wide tree.
//! Meshes placed many times (instances: a 3x4 [`Transform`], an id and a mask each) go to an
//! [`InstancedTracer`], which builds each mesh's tree once and names the instance of every hit.
//!
//! # Which method
//!
//! The default suits most users. To name one ([`TracerBuilder::method`], or `--method` on the
//! command line), by the rays traced:
//!
//! | rays | method |
//! |---|---|
//! | camera rays, shadow rays toward one light (coherent) | `bvh8-sah-packet`, or `kd-stack` for camera rays in rooms |
//! | bounces of a path tracer, ambient occlusion (incoherent) | `bvh8-sah-lists` in large batches, `bvh8-sah` otherwise |
//! | one ray at a time, or a few | `bvh8-sah` (any hit: `bvh8`) |
//! | no stack memory (GPUs, hardware) | `bvh4-hash`, `hash` (Binder & Keller 2016) |
//!
//! Every method's page ([`core::method`]) names its paper and when to pick it.
//!
//! # The expert path, one level down
//!
//! A [`Builder`] makes the canonical tree, [`PreparedScene::new`](core::prepared::PreparedScene::new)
//! derives what the chosen methods read (and rejects a tree built for other triangles), and a
//! backend ([`cpu::CpuBackend`], or `gpu::WgpuBackend` with the `gpu` feature) traces batches
//! through the backend-agnostic [`Trace`](core::trace::Trace) trait:
//!
//! ```
//! use raytrail::prelude::*;
//! # fn main() -> Result<(), raytrail::Error> {
//! let scene = raytrail::core::scene::Scene::from_indexed(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]])?;
//! let method = Method::Wide(WideMethod::BVH8);
//! let prepared = PreparedScene::new(&scene, Builder::Sah.build(&scene)?, &[method])?;
//! let backend = CpuBackend::new();
//! let cpu_scene = backend.prepare(Arc::new(prepared))?;
//! let rays = [Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::new(0.0, 0.0, -1.0), 0.0, f32::INFINITY)];
//! let mut hits = [Hit::MISS];
//! let report = backend.trace(&cpu_scene, &rays, &TraceOptions::new(method), &mut hits)?;
//! assert_eq!((hits[0].prim, report.untraceable), (0, 0));
//! # Ok(())
//! # }
//! ```
//!
//! # Features
//!
//! | feature | default | adds |
//! |---|---|---|
//! | `cpu` | yes | the rayon backend ([`cpu`]), [`Tracer`], `auto`'s method choice ([`analysis`]) |
//! | `loaders` | yes | mesh files ([`mesh`], [`load`]): OBJ, PLY, OFF, STL, glTF, gzip |
//! | `gpu` | no | the wgpu backend (`gpu`): every method as a WGSL kernel; builds wgpu |
//!
//! A CPU-only user who passes triangles from memory depends on
//! `raytrail = { version = "0.1", default-features = false, features = ["cpu"] }`.
//!
//! The crates behind it: [`core`] (the `no_std` core: types, tests, keys, layouts, perfect
//! hashing, state machines), [`build`] (the tree builders), `cpu`, `gpu` and `mesh`. The command
//! line is the `raytrail-cli` package and the conformance suite `raytrail-conformance`;
//! docs/ARCHITECTURE.md tells how the parts fit.
#![warn(missing_docs)]

#[cfg(feature = "cpu")]
pub mod analysis;
mod error;
#[cfg(feature = "cpu")]
mod instanced;
pub mod prelude;
#[cfg(feature = "cpu")]
mod tracer;

pub use error::Error;
#[cfg(feature = "cpu")]
pub use instanced::{InstancedTracer, INSTANCED_DEFAULT};
#[cfg(feature = "cpu")]
pub use tracer::{Tracer, TracerBuilder, AUTO_MIN_RAYS, AUTO_WALKS};

#[doc(inline)]
pub use raytrail_build as build;
#[doc(inline)]
pub use raytrail_core as core;
#[cfg(feature = "cpu")]
#[doc(inline)]
pub use raytrail_cpu as cpu;
#[cfg(feature = "loaders")]
#[doc(inline)]
pub use raytrail_mesh as mesh;
#[cfg(feature = "gpu")]
#[doc(inline)]
pub use raytrail_wgpu as gpu;

pub use raytrail_build::Builder;
pub use raytrail_core::all_hits::{AllHits, AllHitsOptions};
pub use raytrail_core::glam::Vec3;
pub use raytrail_core::instance::{Instance, InstanceHit, Transform};
pub use raytrail_core::method::{Method, Query};
pub use raytrail_core::nearest::NearestPoint;
pub use raytrail_core::{Hit, Ray};

/// Loads a mesh file (`.obj`, `.ply`, `.off`, `.stl`, `.gltf`, `.glb`, any of them gzipped) with
/// the default policy: elements that are not triangles or polygons are skipped
/// ([`mesh::load_with`] counts them and can make them an error).
#[cfg(feature = "loaders")]
pub fn load(path: impl AsRef<std::path::Path>) -> Result<raytrail_core::scene::Mesh, Error> {
    Ok(raytrail_mesh::load(path.as_ref())?)
}
