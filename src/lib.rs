//! raytrail: ray-traversal methods for triangle scenes.
pub use raytrail_conformance as conformance;
pub use raytrail_core as core;
pub use raytrail_cpu as cpu;
