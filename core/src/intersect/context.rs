use super::{SlabPair, SlabRay, TriangleTest};
use crate::Ray;

/// Everything a traversal knows about its ray: the ray and both tests' per-ray constants.
#[derive(Clone, Copy)]
pub struct RayContext<T: TriangleTest> {
    /// The ray as given.
    pub ray: Ray,
    /// Slab-test constants.
    pub slab: SlabRay,
    /// The same constants arranged for testing both child boxes of a node at once.
    pub pair: SlabPair,
    /// Triangle-test constants.
    pub tri: T::PerRay,
    /// A bound on how far a triangle hit's computed `t` may stray from the computed interval of
    /// a box holding the triangle (see [`RayContext::new`]).
    pub t_slack: f32,
}

/// Units of `f32::EPSILON` in [`RayContext::t_slack`]: generous against the few roundings of
/// the watertight test's `t`, small against any real gap between boxes. Shaders receive
/// `SLACK_ULPS * f32::EPSILON` bit for bit.
pub const SLACK_ULPS: f32 = 64.0;

/// Bound on `reach^3 / |d|` below which a ray's distances are reliable (see
/// [`RayContext::is_reliable`]); shaders receive it bit for bit.
pub const RELIABLE_LIMIT: f32 = f32::MAX / 256.0;

impl<T: TriangleTest> RayContext<T> {
    /// Computes the per-ray constants; call only for a traceable ray ([`Ray::is_traceable`]).
    ///
    /// `scene_scale` is the largest coordinate magnitude in the scene. Box distances are computed
    /// to a few ulps of `t`, but a triangle's `t` carries an absolute error of a few ulps of the
    /// vertex coordinates relative to the origin, divided by the direction's size. The slack
    /// bounds that error; comparisons that prune by `t` across boxes must exceed it.
    #[inline]
    pub fn new(ray: &Ray, scene_scale: f32) -> Self {
        let reach = scene_scale + ray.origin().abs().max_element();
        let d = ray.dir().abs().max_element();
        // The watertight test forms products of order reach^3 / |d|; where they come near the
        // float range its `t` is unreliable: the slack is then infinite (see `is_reliable`).
        let t_slack = if reach * reach * (reach / d) < RELIABLE_LIMIT {
            SLACK_ULPS * f32::EPSILON * reach / d
        } else {
            f32::INFINITY
        };
        let slab = SlabRay { slack: t_slack, ..SlabRay::new(ray) };
        Self { ray: *ray, slab, pair: SlabPair::new(&slab), tri: T::prepare(ray), t_slack }
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
        (self.ray.tmin - self.t_slack, limit + self.t_slack)
    }
}
