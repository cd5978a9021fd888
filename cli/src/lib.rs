//! The library half of the `raytrail` command line: what its tests and other tools share with it.
//!
//! - [`fuzz`]: the bodies of the fuzz targets, replayed on their corpus by the tests.
//! - [`npy`]: NumPy ray and hit files, the command line's exchange format.
//! - [`write`](mod@write): writes that never lose a file (a temporary file renamed into place).
//! - [`output`]: printing to stdout and stderr that never panics.
//! - `embree_mesh` (with the `embree` feature): a scene as an Embree triangle geometry.
#![warn(missing_docs)]

#[cfg(feature = "embree")]
pub mod embree_mesh;
pub mod fuzz;
pub mod npy;
pub mod output;
pub mod write;
