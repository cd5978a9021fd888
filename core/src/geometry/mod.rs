//! Plain geometric data: rays, boxes, hits and triangles.

mod aabb;
// Clipping serves only the builders (kd and SBVH), which need the heap.
#[cfg(feature = "alloc")]
pub(crate) mod clip;
mod hit;
mod morton;
mod ray;
mod triangle;

pub use aabb::Aabb;
pub use hit::Hit;
pub(crate) use morton::morton3;
pub use ray::Ray;
pub use triangle::Triangle;
