use super::{SlabPair, SlabRay, TriangleTest};
use crate::Ray;
use core::cell::Cell;

/// Everything a traversal knows about its ray: the ray and both tests' per-ray constants.
///
/// The triangle test's constants are made on first use ([`RayContext::tri`]): most secondary
/// rays leave the scene, or end, without reaching a leaf, and making them up front was a tenth of
/// such a ray's cost. The box constants `B` are what the tree's traversal tests boxes with: the
/// BVH2 methods' [`SlabPair`], or [`NoPair`] for kd-trees, which cross one plane at a time (making
/// a pair they never use was an eighth of a kd ambient-occlusion ray's cost).
#[derive(Clone)]
pub struct RayContext<T: TriangleTest, B: BoxConstants = SlabPair> {
    /// The ray as given.
    pub ray: Ray,
    /// Slab-test constants.
    pub slab: SlabRay,
    /// The slab constants arranged for the tree's own box tests (both child boxes of a BVH2 node
    /// at once), or nothing.
    pub pair: B,
    /// Triangle-test constants, once made.
    tri: Cell<Option<T::PerRay>>,
    /// A bound on how far a triangle hit's computed `t` may stray from the computed interval of
    /// a box holding the triangle (see [`RayContext::new`]).
    pub t_slack: f32,
}

/// Units of `f32::EPSILON` in [`RayContext::t_slack`]: twice the bound derived in
/// [`RayContext::new`] (about 7.5), small against any real gap between boxes. A power of two, so
/// that [`SLACK_SCALE`] is one and scaling by it is exact.
pub const SLACK_ULPS: f32 = 16.0;

/// `SLACK_ULPS * f32::EPSILON` (2^-19): the factor from `reach / |d|` to the slack. Shaders
/// receive it bit for bit.
pub const SLACK_SCALE: f32 = SLACK_ULPS * f32::EPSILON;

/// Bound on `reach^3 / |d|` below which a ray's distances are reliable (see
/// [`RayContext::is_reliable`]); shaders receive it bit for bit.
pub const RELIABLE_LIMIT: f32 = f32::MAX / 256.0;

/// The context of a kd-tree traversal: no box constants beyond [`SlabRay`].
pub type KdRayContext<T> = RayContext<T, NoPair>;

/// Per-ray constants a tree's box tests need beyond [`SlabRay`], made from it.
pub trait BoxConstants: Clone {
    /// The constants of the ray whose slab constants are `slab`.
    fn from_slab(slab: &SlabRay) -> Self;
}

impl BoxConstants for SlabPair {
    #[inline(always)]
    fn from_slab(slab: &SlabRay) -> Self {
        SlabPair::new(slab)
    }
}

/// No box constants beyond [`SlabRay`]: what kd-tree traversals use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoPair;

impl BoxConstants for NoPair {
    #[inline(always)]
    fn from_slab(_: &SlabRay) -> Self {
        NoPair
    }
}

impl<T: TriangleTest, B: BoxConstants> RayContext<T, B> {
    /// Computes the per-ray constants; call only for a traceable ray ([`Ray::is_traceable`]).
    ///
    /// `scene_scale` is the largest coordinate magnitude in the scene. The slack is
    /// `SLACK_SCALE * reach / |d|`, with `reach = scene_scale + max|origin|` and `|d|` the
    /// largest direction component (the watertight test's `d[kz]`). Why it bounds the error:
    ///
    /// - The watertight `t` is `(u az + v bz + w cz) / (u + v + w)` with `u, v, w` of one sign:
    ///   a convex combination of the vertices' `z_i = (p_i[kz] - o[kz]) / d[kz]`, whatever the
    ///   rounding of `u, v, w` (it only moves the point within the triangle's span). Each `z_i`
    ///   is computed to 3 roundings, the weighted sum and the division add 6 more: the computed
    ///   `t` lies within `gamma(9) * max|z_i| <= 4.5 * EPSILON * reach / |d|` of `[min z_i,
    ///   max z_i]`, which lies inside the box's `kz` slab.
    /// - The box side: a near distance rounds up by at most `gamma(3) * |t| <= 1.5 * EPSILON *
    ///   reach / |d|`, and behind the origin the far padding narrows the interval by at most
    ///   twice that. Together about 7.5 units; [`SLACK_ULPS`] is twice that.
    ///
    /// Comparisons that prune by `t` across boxes must exceed the slack. The other two slabs are
    /// not covered by this argument: the rounding of `u, v, w` moves the point sideways by an
    /// amount that grows with the triangle's aspect ratio, so for slivers seen at an angle no
    /// constant slack suffices. `tests/slack_bound.rs` measures both (at most 2.3 units on
    /// well-shaped triangles; a rare tail on slivers), and the conformance suite checks real
    /// meshes end to end.
    #[inline]
    pub fn new(ray: &Ray, scene_scale: f32) -> Self {
        Self::from_slab(ray, SlabRay::with_slack(ray, scene_scale))
    }

    /// The context of `ray` around its slab constants `slab`, made by [`SlabRay::with_slack`]
    /// (a traversal may test its first box with them before it pays for the rest).
    #[inline(always)]
    pub fn from_slab(ray: &Ray, slab: SlabRay) -> Self {
        Self { ray: *ray, slab, pair: B::from_slab(&slab), tri: Cell::new(None), t_slack: slab.slack }
    }

    /// The triangle test's per-ray constants, made on the first call.
    #[inline(always)]
    pub fn tri(&self) -> T::PerRay {
        match self.tri.get() {
            Some(t) => t,
            None => {
                let t = T::prepare(&self.ray);
                self.tri.set(Some(t));
                t
            }
        }
    }

    /// Whether the ray's distances across the scene stay clear of the float range. Where they do
    /// not (directions around 1e-30 and below for a unit-size scene), the triangle test's products
    /// overflow and no method can answer reliably: every method treats such a ray as a miss.
    #[inline(always)]
    pub fn is_reliable(&self) -> bool {
        self.t_slack.is_finite()
    }

    /// The interval boxes are tested over when the closest candidate so far is at `limit`:
    /// `[tmin, limit]` widened by the slack on both ends, so a box is never culled while a
    /// triangle inside it could still yield a computed `t` within `[tmin, limit]`.
    #[inline(always)]
    pub fn box_interval(&self, limit: f32) -> (f32, f32) {
        self.slab.widen(self.ray.tmin, limit)
    }
}

impl SlabRay {
    /// The slab constants of a traceable ray ([`Ray::is_traceable`]) with their slack set to the
    /// [`RayContext::t_slack`] of a scene whose largest coordinate magnitude is `scene_scale`
    /// (infinite where the ray is not reliable; see [`RayContext::new`]).
    #[inline(always)]
    pub fn with_slack(ray: &Ray, scene_scale: f32) -> Self {
        let reach = scene_scale + ray.origin().abs().max_element();
        let slab = SlabRay::new(ray);
        // `1 / |d|` without a division of its own: rounding is monotonic, so the smallest
        // `|1 / d_i|` is exactly `1 / max |d_i|` rounded (zero components give `inf`, never the
        // smallest for a traceable ray). A scalar division here was a fifth of the time of a ray
        // that leaves the scene after a node or two.
        let reach_per_d = reach * slab.inv_dir.abs().min_element();
        // The watertight test forms products of order reach^3 / |d|; where they come near the
        // float range its `t` is unreliable: the slack is then infinite (see `is_reliable`).
        // Scaling by the power of two `SLACK_SCALE` is exact.
        let slack =
            if reach * reach * reach_per_d < RELIABLE_LIMIT { reach_per_d * SLACK_SCALE } else { f32::INFINITY };
        SlabRay { slack, ..slab }
    }

    /// `[tmin, limit]` widened by the slack on both ends (see [`RayContext::box_interval`]).
    #[inline(always)]
    pub fn widen(&self, tmin: f32, limit: f32) -> (f32, f32) {
        (tmin - self.slack, limit + self.slack)
    }
}
