//! Tracing a batch in an order of the backend's choosing: rays that start near each other and
//! point into the same octant are traced one after another, so that the nodes and leaves one ray
//! brings into the caches serve the next. Garanzha & Loop (2010, Sec. 3.1) sort rays by a key of
//! their origin and direction cells ahead of their frustum traversal for the same reason; this key
//! serves the depth-first walks, whose packets need rays of one octant and whose single rays gain
//! from neighbours that touch the same nodes. Each ray's answer is its own, so an order changes the
//! speed and never the hits.

use crate::{Aabb, Ray};
use glam::Vec3;

/// The order a backend traces a batch's rays in. Hits are written back in the order given either
/// way: every ray's answer is the same in any order, only the time differs. A backend that has
/// only one order (the serial reference, the GPU) traces the rays as given.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum TraceOrder {
    /// As given: the order of a camera's tiles or of a renderer's own sort is kept.
    #[default]
    AsGiven,
    /// Sorted by [`OriginOctantKey`] before tracing, hits scattered back: for rays in no useful
    /// order (a path tracer's later bounces, shuffled batches). Costs a sort and two passes over
    /// the batch, a small part of tracing it.
    Sorted,
}

impl TraceOrder {
    /// The order `auto` traces a batch in: [`TraceOrder::Sorted`] for a batch of at least
    /// [`SORT_MIN_RAYS`] whose neighbouring rays neither point alike ([`looks_coherent`]) nor
    /// start close together ([`origins_look_scattered`]), [`TraceOrder::AsGiven`] otherwise: a
    /// camera's rays, shadow rays to one light, and a renderer's bounces in pixel order (several
    /// rays from one hit point, then the next pixel's), where sorting costs more than it gains.
    /// Ambient-occlusion rays in the bench's pixel order, sorted, ran at 0.41-0.85 of the fastest
    /// method as given: fast any-hit rays, whose neighbours already share their nodes
    /// (`docs/notes/*-sorted-trace-order.md`, "Which batches to sort"). `auto` also sorts only
    /// rays slow enough to pay for it (`raytrail::analysis::order`).
    pub fn for_batch(rays: &[Ray]) -> TraceOrder {
        if rays.len() >= SORT_MIN_RAYS && !looks_coherent(rays) && origins_look_scattered(rays) {
            TraceOrder::Sorted
        } else {
            TraceOrder::AsGiven
        }
    }
}

/// Fewest rays `auto` sorts ([`TraceOrder::for_batch`]): the sort pays through rays that start
/// close together, and a smaller batch holds fewer of them per cell of the scene. At 2^17 the
/// diffuse bounces of the kitchen and the dragon seen from outside (98,156 and 69,003 rays at
/// 512 x 512) were traced unsorted, at 0.82-0.91 of the fastest method, which was a sorted walk;
/// at 2^16 `auto` sorts them and ran at 0.86-1.02 (`docs/notes/*-auto-sorts-smaller-batches.md`).
pub const SORT_MIN_RAYS: usize = 1 << 16;

/// Up to 32 pairs of neighbouring rays spread evenly over the batch: what the batch tests judge
/// its order by.
fn neighbour_pairs(rays: &[Ray]) -> impl Iterator<Item = (&Ray, &Ray)> {
    let pairs = rays.len().saturating_sub(1).min(32);
    let step = rays.len().saturating_sub(1) / pairs.max(1);
    (0..pairs).map(move |k| (&rays[k * step], &rays[k * step + 1]))
}

/// Whether neighbouring rays of the batch point alike, judged on up to 32 pairs of neighbours
/// spread over it: at least a quarter of them within about 18 degrees of each other, as
/// neighbouring camera rays are. Two directions drawn at random over a hemisphere pass that test
/// about one time in twenty.
pub fn looks_coherent(rays: &[Ray]) -> bool {
    if rays.len() < 2 {
        return true;
    }
    let (mut pairs, mut close) = (0, 0);
    for (a, b) in neighbour_pairs(rays) {
        let (a, b) = (a.dir(), b.dir());
        // cos > 0.95 without a square root: `a.b > 0` and `(a.b)^2 > 0.95^2 |a|^2 |b|^2`.
        let dot = a.dot(b);
        pairs += 1;
        close += usize::from(dot > 0.0 && dot * dot > 0.9025 * a.length_squared() * b.length_squared());
    }
    close * 4 >= pairs
}

/// Whether neighbouring rays of the batch start far apart, judged on the same pairs as
/// [`looks_coherent`]: fewer than a quarter of them start within 1/32 of the diagonal of the box
/// of the pairs' origins. Two origins drawn at random in a room pass that test well under one
/// time in a hundred; rays in pixel order fail it (bounces of one pixel share their origin, the
/// next pixel's start beside them).
pub fn origins_look_scattered(rays: &[Ray]) -> bool {
    let mut bounds = Aabb::EMPTY;
    for (a, b) in neighbour_pairs(rays) {
        bounds = bounds.grow(a.origin()).grow(b.origin());
    }
    let extent = bounds.max - bounds.min;
    let near = extent.length_squared() / (32.0 * 32.0);
    let (mut pairs, mut close) = (0, 0);
    for (a, b) in neighbour_pairs(rays) {
        pairs += 1;
        // NaN distances (non-finite origins) count as far; an infinite box makes every pair near.
        close += usize::from((a.origin() - b.origin()).length_squared() <= near);
    }
    pairs > 0 && close * 4 < pairs
}

/// Bits of each origin axis's cell index in [`OriginOctantKey`]: `3 x 9` bits of Morton code below
/// the octant's 3, in 30 bits.
const AXIS_BITS: u32 = 9;

/// The sort key of [`TraceOrder::Sorted`]: the direction's octant (the sign bits of its components)
/// above the Morton code of the origin's cell on a `512^3` grid over the batch's origins. Rays of
/// one octant come together, so the packet walks' octant groups fill, and within an octant rays
/// follow the Z curve through space, so consecutive rays start in the same part of the tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OriginOctantKey {
    lo: Vec3,
    cells_per_unit: Vec3,
}

impl OriginOctantKey {
    /// Bits of a key.
    pub const BITS: u32 = 3 + 3 * AXIS_BITS;

    /// The key over `origins`, the box of the batch's origins (an empty or non-finite box puts every
    /// origin in one cell, leaving the octant alone to order by).
    pub fn new(origins: Aabb) -> OriginOctantKey {
        let cells = (1u32 << AXIS_BITS) as f32;
        let extent = origins.max - origins.min;
        let per_unit = |e: f32| if e > 0.0 && e.is_finite() { cells / e } else { 0.0 };
        let lo = if origins.min.is_finite() { origins.min } else { Vec3::ZERO };
        OriginOctantKey { lo, cells_per_unit: Vec3::new(per_unit(extent.x), per_unit(extent.y), per_unit(extent.z)) }
    }

    /// The ray's key (30 bits). Any ray has one: a NaN or far-off origin saturates to a border
    /// cell, and a ray that cannot be traced is sorted like any other (its answer is a miss in any
    /// order).
    #[inline]
    pub fn key(&self, ray: &Ray) -> u32 {
        let rel = (ray.origin() - self.lo) * self.cells_per_unit;
        // `as u32` saturates and maps NaN to 0.
        let cell = |x: f32| (x as u32).min((1 << AXIS_BITS) - 1);
        let d = ray.dir;
        let octant = u32::from(d[0].is_sign_negative())
            | u32::from(d[1].is_sign_negative()) << 1
            | u32::from(d[2].is_sign_negative()) << 2;
        octant << (3 * AXIS_BITS) | crate::geometry::morton3(cell(rel.x), cell(rel.y), cell(rel.z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate alloc;
    use alloc::vec::Vec;

    fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
        Ray { origin: o, tmin: 0.0, dir: d, tmax: f32::INFINITY }
    }

    #[test]
    fn the_octant_orders_first_then_the_origin_along_the_z_curve() {
        let k = OriginOctantKey::new(Aabb { min: Vec3::ZERO, max: Vec3::ONE });
        let near = k.key(&ray([0.1, 0.1, 0.1], [1.0, 1.0, 1.0]));
        let far = k.key(&ray([0.9, 0.9, 0.9], [1.0, 1.0, 1.0]));
        let other_octant = k.key(&ray([0.1, 0.1, 0.1], [-1.0, 1.0, 1.0]));
        assert!(near < far && far < other_octant, "{near} {far} {other_octant}");
        assert_eq!(k.key(&ray([1.0, 1.0, 1.0], [-0.0, -1.0, -1.0])), (1 << 30) - 1);
    }

    /// Shuffled rays are sorted; rays in pixel order (four bounces per origin, origins side by
    /// side) and rays of one camera are not; a small batch is not.
    #[test]
    fn only_large_batches_in_no_order_are_sorted() {
        let mut state = 0x853c_49e6_748f_ea9bu64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 - 0.5
        };
        let n = SORT_MIN_RAYS;
        let shuffled: Vec<Ray> = (0..n).map(|_| ray([next(), next(), next()], [next(), next(), next()])).collect();
        assert_eq!(TraceOrder::for_batch(&shuffled), TraceOrder::Sorted);
        assert_eq!(TraceOrder::for_batch(&shuffled[..n - 1]), TraceOrder::AsGiven);
        let pixel_order: Vec<Ray> =
            (0..n).map(|i| ray([(i / 4) as f32 * 1e-5, 0.0, 0.0], [next(), next(), next()])).collect();
        assert!(!looks_coherent(&pixel_order) && !origins_look_scattered(&pixel_order));
        assert_eq!(TraceOrder::for_batch(&pixel_order), TraceOrder::AsGiven);
        let camera: Vec<Ray> = (0..n).map(|i| ray([0.0; 3], [1.0, (i % 512) as f32 * 1e-3, 0.2])).collect();
        assert_eq!(TraceOrder::for_batch(&camera), TraceOrder::AsGiven);
    }

    #[test]
    fn odd_origins_and_boxes_still_get_keys() {
        let k = OriginOctantKey::new(Aabb::EMPTY);
        assert_eq!(k.key(&ray([5.0, -3.0, 1e30], [1.0, 0.0, 0.0])), 0);
        let k = OriginOctantKey::new(Aabb { min: Vec3::ZERO, max: Vec3::ONE });
        assert_eq!(k.key(&ray([f32::NAN, -1.0, 2.0], [1.0, 1.0, 1.0])), crate::geometry::morton3(0, 0, 511));
    }
}
