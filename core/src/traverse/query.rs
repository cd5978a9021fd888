use crate::intersect::TriangleHit;
use crate::method::Query;
use crate::{Hit, Ray};

/// The answer being built for one ray.
#[derive(Clone, Copy, Debug)]
pub struct QueryState {
    /// Closest hit so far (or the any-hit answer).
    pub hit: Hit,
    /// Stop at the first hit.
    pub any: bool,
    /// The ray's own interval end.
    tmax: f32,
}

impl QueryState {
    /// An empty answer to `query` for `ray`.
    #[inline(always)]
    pub fn new(ray: &Ray, query: Query) -> Self {
        Self { hit: Hit::MISS, any: query.is_any(), tmax: ray.tmax }
    }

    /// The answer so far `hit` to `query` for a ray whose interval ends at `tmax`: what
    /// [`QueryState::new`] and the offers since made, for state kept by lane rather than by ray.
    #[inline(always)]
    pub fn resume(hit: Hit, tmax: f32, query: Query) -> Self {
        Self { hit, any: query.is_any(), tmax }
    }

    /// Current culling distance: the closest hit so far, or the ray's `tmax`. Inclusive, so a
    /// candidate at exactly this distance is still tested and ties resolve by primitive id.
    #[inline(always)]
    pub fn limit(&self) -> f32 {
        if self.hit.is_hit() {
            self.hit.t
        } else {
            self.tmax
        }
    }

    /// Offers a triangle hit (already inside `[tmin, limit]`); returns whether it was taken.
    #[inline(always)]
    pub fn offer(&mut self, h: TriangleHit, prim: u32) -> bool {
        if !self.hit.is_hit() || self.hit.is_beaten_by(h.t, prim) {
            self.hit = Hit { t: h.t, prim, u: h.u, v: h.v };
            true
        } else {
            false
        }
    }

    /// Whether the query is answered (an any-hit query that found a hit).
    #[inline(always)]
    pub fn is_answered(&self) -> bool {
        self.any && self.hit.is_hit()
    }
}
