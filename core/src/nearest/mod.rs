//! The nearest point on the mesh to a query point, within a search radius: for placing points on
//! a surface, signed-distance and collision queries, snapping (Embree's `rtcPointQuery`, the `bvh`
//! crate's nearest-point request).
//!
//! - [`closest_point_on_triangle`]: one triangle, exactly the region rule (vertex, edge or face
//!   nearest) in `f32`;
//! - [`nearest_point_in`] (`walk.rs`): a wide tree walked nearest box first, culling boxes
//!   farther than the best distance so far; [`nearest_point`] in a prepared scene's frame, and a
//!   batch ([`nearest_points`]); [`framed_query`], [`query_bound`] and [`unframed`], the steps
//!   around the walk that a backend with a walk of its own (the GPU's) takes alike.
//!
//! Ties (two triangles at one distance, as at a shared edge or vertex) go to the lower primitive
//! id, as hits do, so the answer does not depend on the tree.

mod triangle;
mod walk;

pub use triangle::{closest_point_on_triangle, PointOnTriangle};
pub use walk::{framed_query, nearest_point, nearest_point_in, nearest_points, query_bound, unframed};

/// The point of the mesh nearest to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NearestPoint {
    /// The triangle it lies on (its primitive id).
    pub prim: u32,
    /// Barycentric weight of the triangle's second vertex at the point.
    pub u: f32,
    /// Barycentric weight of its third vertex (the first's is `1 - u - v`).
    pub v: f32,
    /// The point.
    pub point: [f32; 3],
    /// Its distance from the query point.
    pub distance: f32,
}
