//! The hit lists of a batch of rays, one after another in one buffer (as Open3D's
//! `list_intersections` and trimesh's `intersects_location` return them): ray `i`'s hits are
//! `hits[offsets[i]..offsets[i + 1]]`.

use super::walk::all_hits_framed;
use super::AllHitsOptions;
use crate::prepared::PreparedScene;
use crate::{Error, Hit, Ray};
use alloc::vec::Vec;

/// Every ray's hits in order of `t` ([`super`]), and which lists were cut at the limit.
#[derive(Clone, Debug, PartialEq)]
pub struct AllHits {
    hits: Vec<Hit>,
    offsets: Vec<usize>,
    truncated: Vec<bool>,
}

impl Default for AllHits {
    fn default() -> Self {
        AllHits { hits: Vec::new(), offsets: alloc::vec![0], truncated: Vec::new() }
    }
}

impl AllHits {
    /// The lists of `rays` in `scene`, one ray after another on this thread (a backend splits a
    /// batch into chunks and [`AllHits::append`]s their lists). [`Error::NotPrepared`] for a
    /// scene without a wide tree.
    pub fn trace(scene: &PreparedScene, rays: &[Ray], options: &AllHitsOptions) -> Result<AllHits, Error> {
        let tree = scene.query_tree()?;
        let mut out = AllHits::default();
        let mut stack = Vec::new();
        out.offsets.reserve(rays.len());
        out.truncated.reserve(rays.len());
        for ray in rays {
            let cut = all_hits_framed(scene, tree, ray, options, &mut out.hits, &mut stack);
            out.truncated.push(cut);
            out.offsets.push(out.hits.len());
        }
        Ok(out)
    }

    /// Appends the list of one more ray: `hits` in order of `(t, prim)`, and whether it was cut
    /// at the limit (for a backend that makes the lists itself).
    pub fn push(&mut self, hits: &[Hit], truncated: bool) {
        self.hits.extend_from_slice(hits);
        self.offsets.push(self.hits.len());
        self.truncated.push(truncated);
    }

    /// Appends the lists of `other` (the rays after these).
    pub fn append(&mut self, other: AllHits) {
        let base = self.hits.len();
        self.hits.extend_from_slice(&other.hits);
        self.offsets.extend(other.offsets[1..].iter().map(|o| o + base));
        self.truncated.extend_from_slice(&other.truncated);
    }

    /// Rays.
    pub fn len(&self) -> usize {
        self.truncated.len()
    }

    /// Whether there are no rays.
    pub fn is_empty(&self) -> bool {
        self.truncated.is_empty()
    }

    /// The hits of ray `i` in order of `(t, prim)`: empty for a miss, one [`Hit::REFUSED`] for a
    /// ray no method answers exactly; `None` past the last ray.
    pub fn ray(&self, i: usize) -> Option<&[Hit]> {
        Some(&self.hits[*self.offsets.get(i)?..*self.offsets.get(i + 1)?])
    }

    /// Whether ray `i` had more hits than [`AllHitsOptions::max_hits`] (its list holds the
    /// nearest ones).
    pub fn is_truncated(&self, i: usize) -> bool {
        self.truncated.get(i).copied().unwrap_or(false)
    }

    /// Every list, one ray after another.
    pub fn hits(&self) -> &[Hit] {
        &self.hits
    }

    /// Where each ray's list starts in [`AllHits::hits`], and the end: one more than the rays.
    pub fn offsets(&self) -> &[usize] {
        &self.offsets
    }

    /// The lists in ray order.
    pub fn iter(&self) -> impl Iterator<Item = &[Hit]> + '_ {
        self.offsets.windows(2).map(|w| &self.hits[w[0]..w[1]])
    }
}
