use crate::intersect::TriangleHit;
use crate::method::Query;
use crate::{Hit, Ray};

/// The answer being built for one ray.
#[derive(Clone, Copy, Debug)]
pub struct QueryState {
    /// Closest hit so far (or the any-hit answer).
    hit: Hit,
    /// Stop at the first hit.
    pub any: bool,
    /// [`QueryState::limit`], kept beside the hit: the walks read it at every node, and working
    /// it out of the hit each time (a test of the hit's id and a select) was 3% of a single ray's
    /// instructions (`docs/notes/*-single-ray-selects.md`).
    limit: f32,
}

impl QueryState {
    /// An empty answer to `query` for `ray`.
    #[inline(always)]
    pub fn new(ray: &Ray, query: Query) -> Self {
        Self { hit: Hit::MISS, any: query.is_any(), limit: ray.tmax }
    }

    /// The answer so far `hit` to `query` for a ray whose interval ends at `tmax`: what
    /// [`QueryState::new`] and the offers since made, for state kept by lane rather than by ray.
    #[inline(always)]
    pub fn resume(hit: Hit, tmax: f32, query: Query) -> Self {
        Self { hit, any: query.is_any(), limit: if hit.is_hit() { hit.t } else { tmax } }
    }

    /// Closest hit so far (or the any-hit answer); [`Hit::MISS`] while there is none.
    #[inline(always)]
    pub fn hit(&self) -> Hit {
        self.hit
    }

    /// Current culling distance: the closest hit so far, or the ray's `tmax`. Inclusive, so a
    /// candidate at exactly this distance is still tested and ties resolve by primitive id.
    #[inline(always)]
    pub fn limit(&self) -> f32 {
        self.limit
    }

    /// Offers a triangle hit (already inside `[tmin, limit]`); returns whether it was taken.
    #[inline(always)]
    pub fn offer(&mut self, h: TriangleHit, prim: u32) -> bool {
        if !self.hit.is_hit() || self.hit.is_beaten_by(h.t, prim) {
            self.hit = Hit { t: h.t, prim, u: h.u, v: h.v };
            self.limit = h.t;
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
