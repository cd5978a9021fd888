//! Every hit along a ray, in order of distance, each triangle once: what a renderer of
//! transparent surfaces, a thickness or inside test, or a re-cast loop around the closest hit
//! needs (trimesh's `multiple_hits`, Open3D's `list_intersections`).
//!
//! - [`AllHitsOptions`]: at most how many hits per ray, and whether hits at one distance count
//!   once;
//! - [`HitList`] (`collect.rs`): the list of one ray as it is found (sorted, merged and cut to the
//!   limit, which then culls the walk);
//! - [`all_hits`] (`walk.rs`): the walk of a wide tree that finds them, and [`all_hits_framed`]
//!   for a ray as the caller gives it;
//! - [`AllHits`]: the lists of a batch, one after another.
//!
//! Each leaf is visited at most once per ray, and a triangle in several leaves (a tree with
//! spatial splits) gives the same hit in each, which the list keeps once; so no triangle is
//! reported twice. A ray through an edge two triangles share gets both, as two hits
//! at one `t` (with [`AllHitsOptions::merge_equal_t`], only the one of the lower primitive id).
//! A hit is bit for bit what the closest-hit methods would report for that triangle alone, so the
//! first hit of a list is the ray's closest hit.

mod batch;
mod collect;
mod walk;

pub use batch::AllHits;
pub use collect::HitList;
pub use walk::{all_hits, all_hits_framed, Postponed};

/// What an all-hits query keeps of each ray's hits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AllHitsOptions {
    /// At most this many hits per ray: the nearest ones. A ray with more has its list cut here
    /// and marked truncated ([`AllHits::is_truncated`]); beyond the limit the walk culls as a
    /// closest-hit walk does beyond its hit.
    pub max_hits: usize,
    /// Hits at the same `t` (as numbers: `-0.0` is `0.0`) count once: the one of the lower
    /// primitive id, as the closest hit breaks ties. A ray through a shared edge or vertex then meets the surface once.
    pub merge_equal_t: bool,
}

impl Default for AllHitsOptions {
    /// Every hit ([`usize::MAX`]), none merged.
    fn default() -> Self {
        AllHitsOptions { max_hits: usize::MAX, merge_equal_t: false }
    }
}
