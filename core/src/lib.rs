//! raytrail-core: the `no_std` heart of raytrail.
//!
//! Everything a traversal needs and nothing it does not: ray, box and hit types, the robust box and
//! triangle tests, key and bit-trail arithmetic, node layouts, perfect hashing and the traversal
//! state machines. Builders and table construction need the `alloc` feature; timing needs `std` (the
//! default). Mesh files are the `raytrail-mesh` crate.
//!
//! The canonical tree ([`bvh2::Bvh2`]) is the single source of truth: every layout is a view of it,
//! and node identity in enumerations is the node's index in the canonical tree.
#![no_std]
#![warn(missing_docs)]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

#[cfg(feature = "alloc")]
pub mod all_hits;
pub mod bvh2;
pub mod error;
pub mod geometry;
pub mod hash;
#[cfg(feature = "alloc")]
pub mod instance;
pub mod intersect;
pub mod kd;
pub mod key;
pub mod method;
#[cfg(feature = "alloc")]
pub mod nearest;
pub mod observe;
#[cfg(feature = "alloc")]
pub mod prepared;
#[cfg(feature = "alloc")]
pub mod scene;
#[cfg(feature = "alloc")]
pub mod stream;
#[cfg(feature = "alloc")]
pub mod trace;
pub mod trace_order;
pub mod traverse;
pub mod wide;

pub use error::Error;
pub use geometry::{Aabb, Hit, Ray};
/// The vector library of the public API, re-exported so callers use the same version.
pub use glam;
pub use method::{Bvh2Method, KdMethod, Method, Query, StreamMethod, WideMethod};
