//! The names a first program needs: `use raytrail::prelude::*;`.

pub use crate::{load_scene, Builder};
pub use raytrail_core::glam::Vec3;
pub use raytrail_core::method::{Bvh2Method, KdMethod, Method, Query};
pub use raytrail_core::prepared::PreparedScene;
pub use raytrail_core::trace::{Record, Report, Trace, TraceOptions};
pub use raytrail_core::{Hit, Ray};
pub use raytrail_cpu::CpuBackend;
pub use std::sync::Arc;
