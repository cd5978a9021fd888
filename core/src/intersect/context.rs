use super::{SlabRay, TriangleTest};
use crate::Ray;

/// Everything a traversal knows about its ray: the ray and both tests' per-ray constants.
#[derive(Clone, Copy)]
pub struct RayContext<T: TriangleTest> {
    /// The ray as given.
    pub ray: Ray,
    /// Slab-test constants.
    pub slab: SlabRay,
    /// Triangle-test constants.
    pub tri: T::PerRay,
}

impl<T: TriangleTest> RayContext<T> {
    /// Computes the per-ray constants; call only for a traceable ray ([`Ray::is_traceable`]).
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        Self { ray: *ray, slab: SlabRay::new(ray), tri: T::prepare(ray) }
    }
}
