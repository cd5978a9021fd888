//! The names a first program needs: `use raytrail::prelude::*;`.

#[cfg(feature = "loaders")]
pub use crate::load;
pub use crate::{Builder, Error};
#[cfg(feature = "cpu")]
pub use crate::{InstancedTracer, Tracer, TracerBuilder};
pub use raytrail_core::all_hits::{AllHits, AllHitsOptions};
pub use raytrail_core::glam::Vec3;
pub use raytrail_core::instance::{Instance, InstanceHit, Transform};
pub use raytrail_core::method::{Bvh2Method, KdMethod, Method, Query, StreamMethod, WideMethod};
pub use raytrail_core::nearest::NearestPoint;
pub use raytrail_core::prepared::PreparedScene;
pub use raytrail_core::scene::{Mesh, Scene};
pub use raytrail_core::trace::{Record, Report, Trace, TraceOptions};
pub use raytrail_core::{Hit, Ray};
#[cfg(feature = "cpu")]
pub use raytrail_cpu::CpuBackend;
pub use std::sync::Arc;
