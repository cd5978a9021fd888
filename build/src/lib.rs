//! raytrail-build: the builders of the canonical BVH2 every method is prepared from.
//!
//! - [`Builder`]: which builder makes the tree, by name (`best`, `sah`, `ploc`); [`Builder::Best`]
//!   builds both and keeps the tree of the lower SAH cost.
//! - [`ploc`]: obvhs's PLOC with reinsertion (Meister & Bittner 2018), converted to the core's tree
//!   and kept within the depth the 64-bit keys allow.
//!
//! The binned SAH builder itself is the core's ([`raytrail_core::bvh2::SahBuilder`]), so that a
//! `no_std` user builds trees without this crate.
#![warn(missing_docs)]

mod builder;
pub mod ploc;

pub use builder::Builder;
