//! The one error type of the `raytrail` crate: what failed, with its cause behind `source()`.

use std::fmt;

/// What can go wrong in `raytrail`. Every public function of the crate returns it; match on the
/// variant to tell the failures apart, or print it (`Display` is one line naming the problem).
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// The core refused the scene, the tree or the trace: no triangles, a vertex index past the
    /// vertices, a NaN coordinate, a tree built for other triangles, a buffer of the wrong length,
    /// a method the backend cannot run, a device failure (the variant says which).
    Core(raytrail_core::Error),
    /// A mesh file could not be loaded (the file, the line or byte, and why).
    #[cfg(feature = "loaders")]
    Mesh(raytrail_mesh::MeshError),
    /// Rays that cannot hit anything as given (a NaN or infinite component, a zero direction, a
    /// NaN bound or `tmin > tmax`), where the tracer was told to reject them
    /// ([`crate::TracerBuilder::reject_untraceable`]); otherwise they are misses, counted in
    /// [`Report::untraceable`](raytrail_core::trace::Report::untraceable).
    UntraceableRays {
        /// How many rays of the batch.
        count: usize,
        /// The index of the first.
        first: usize,
    },
    /// The ray lies outside the numeric range every method answers exactly (an origin farther
    /// than [`FAR_LIMIT`](raytrail_core::prepared::FAR_LIMIT), 2^32, times the scene's size, or
    /// a direction too short to trace reliably), so it was refused rather than answered wrongly;
    /// a batch answers such rays with [`Hit::REFUSED`](raytrail_core::Hit::REFUSED) instead.
    RefusedRay,
    /// A nearest-point search radius that is NaN or negative ([`crate::Tracer::nearest_points`];
    /// `f32::INFINITY` searches the whole mesh).
    InvalidRadius(f32),
    /// A thread pool for [`crate::TracerBuilder::threads`] could not be made.
    #[cfg(feature = "cpu")]
    ThreadPool(raytrail_cpu::ThreadPoolBuildError),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Core(e) => e.fmt(f),
            #[cfg(feature = "loaders")]
            Error::Mesh(e) => e.fmt(f),
            Error::UntraceableRays { count, first } => write!(
                f,
                "{count} untraceable ray(s), the first at index {first}: a NaN or infinite component, a zero \
                 direction, a NaN bound or tmin > tmax"
            ),
            Error::RefusedRay => f.write_str("the ray lies outside the numeric range the methods answer exactly"),
            Error::InvalidRadius(r) => {
                write!(f, "search radius {r}: must be zero or more (f32::INFINITY for no limit)")
            }
            #[cfg(feature = "cpu")]
            Error::ThreadPool(e) => write!(f, "cannot make the thread pool: {e}"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Core(e) => Some(e),
            #[cfg(feature = "loaders")]
            Error::Mesh(e) => Some(e),
            #[cfg(feature = "cpu")]
            Error::ThreadPool(e) => Some(e),
            Error::UntraceableRays { .. } | Error::RefusedRay | Error::InvalidRadius(_) => None,
        }
    }
}

impl From<raytrail_core::Error> for Error {
    fn from(e: raytrail_core::Error) -> Self {
        Error::Core(e)
    }
}

#[cfg(feature = "loaders")]
impl From<raytrail_mesh::MeshError> for Error {
    fn from(e: raytrail_mesh::MeshError) -> Self {
        Error::Mesh(e)
    }
}
