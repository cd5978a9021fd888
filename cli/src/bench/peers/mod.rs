//! Peer libraries traced on the same rays, in the same process, on the same thread pool.
//!
//! Each peer is built with its own builder and traced twice: with its own triangle test, and with
//! raytrail's watertight test (prepared once per ray, called per triangle) in its closest-hit or
//! any-hit callback, so that differences from the triangle test and from the traversal are told
//! apart. The watertight variants also keep raytrail's closest-hit tie rule (equal `t`: smaller
//! primitive id) and its inclusive interval, so their hits can match raytrail's bit for bit.
//!
//! Embree (`embree` and `embree-high`, with the `embree` cargo feature) is traced with its own test only: its traversal takes
//! no per-triangle callback short of a user geometry, which would not be Embree's fast path.

mod bvh_crate;
#[cfg(feature = "embree")]
mod embree;
mod obvhs;

use super::report::Built;
use super::target::{BenchTarget, TargetKind, Targets, Work};
use rayon::prelude::*;
use raytrail::core::method::Query;
use raytrail::core::scene::Scene;
use raytrail::core::{Hit, Ray};
use std::sync::Arc;

/// Rays per parallel task: the CPU backend's chunk size, so both split work alike.
const CHUNK: usize = 256;

/// Which triangle test a peer's callback uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// The peer's own test and hit rule.
    Own,
    /// raytrail's watertight test and tie rule.
    Watertight,
}

impl Variant {
    /// Suffix of the target name.
    fn suffix(self) -> &'static str {
        match self {
            Variant::Own => "",
            Variant::Watertight => "+wt",
        }
    }
}

/// Builds the peers named in `names` over `scene` on `pool`; returns their targets (own test, then
/// watertight, per peer) and what each build cost.
pub fn build(names: &[String], scene: &Scene, pool: &rayon::ThreadPool) -> Result<(Targets, Vec<Built>), String> {
    let mut targets: Targets = Vec::new();
    let mut built = Vec::new();
    for name in names {
        #[cfg(feature = "embree")]
        if let Some(quality) = embree::Quality::from_name(name) {
            let (target, b) =
                embree::Embree::new(scene, pool.current_num_threads(), quality).map_err(|e| e.to_string())?;
            targets.push(Box::new(target));
            built.push(b);
            continue;
        }
        let b = match name.as_str() {
            "obvhs-bvh2" => both_variants(name, pool.install(|| obvhs::ObvhsScene::bvh2(scene)), &mut targets),
            "obvhs-cwbvh" => both_variants(name, pool.install(|| obvhs::ObvhsScene::cwbvh(scene)), &mut targets),
            "bvh" => both_variants(name, pool.install(|| bvh_crate::BvhScene::new(scene)), &mut targets),
            other => return Err(format!("unknown peer '{other}'")),
        };
        built.push(b);
    }
    Ok((targets, built))
}

/// The target names a peer adds: its own test and, where it has one, the watertight variant.
pub fn target_names(peer: &str) -> Vec<String> {
    let mut names = vec![peer.to_string()];
    if !is_embree(peer) {
        names.push(format!("{peer}{}", Variant::Watertight.suffix()));
    }
    names
}

/// Whether `peer` names Embree (at either build quality), which has only its own test.
pub fn is_embree(peer: &str) -> bool {
    matches!(peer, "embree" | "embree-high")
}

/// Adds the two targets of a built peer tree (its own test, then raytrail's watertight one);
/// returns what the build cost.
fn both_variants<P: PeerTree>(name: &str, (tree, built): (P, Built), targets: &mut Targets) -> Built {
    let tree = Arc::new(tree);
    targets.push(Box::new(PeerTarget::new(name, tree.clone(), Variant::Own)));
    targets.push(Box::new(PeerTarget::new(name, tree, Variant::Watertight)));
    built
}

/// A peer's tree: one ray's closest hit or any hit through the peer's traversal, with the peer's
/// own triangle test or, when `WT`, raytrail's watertight test and tie rule; each returns the hit
/// and the triangle tests made (counted only when `COUNT`).
pub trait PeerTree: Send + Sync + 'static {
    /// Closest hit of one ray.
    fn closest<const WT: bool, const COUNT: bool>(&self, ray: &Ray) -> (Hit, u64);
    /// Any hit of one ray.
    fn any<const WT: bool, const COUNT: bool>(&self, ray: &Ray) -> (Hit, u64);
    /// The work per ray this peer can report, from its triangle tests per ray.
    fn work(tests_per_ray: f64) -> Work {
        Work { tests: Some(tests_per_ray), ..Work::default() }
    }
}

/// One peer tree traced with one triangle test: a bench target.
pub struct PeerTarget<P> {
    name: String,
    tree: Arc<P>,
    variant: Variant,
}

impl<P: PeerTree> PeerTarget<P> {
    /// The target `peer` (plus the variant's suffix) over `tree`.
    pub fn new(peer: &str, tree: Arc<P>, variant: Variant) -> Self {
        Self { name: format!("{peer}{}", variant.suffix()), tree, variant }
    }

    /// Traces every ray; returns the triangle tests made (0 unless `COUNT`).
    fn run<const COUNT: bool>(
        &self,
        pool: &rayon::ThreadPool,
        rays: &[Ray],
        query: Query,
        hits: &mut [Hit],
    ) -> Result<u64, String> {
        let t = &*self.tree;
        match (self.variant, query) {
            (Variant::Own, Query::Closest) => par_trace(pool, rays, hits, |r| t.closest::<false, COUNT>(r)),
            (Variant::Own, Query::Any) => par_trace(pool, rays, hits, |r| t.any::<false, COUNT>(r)),
            (Variant::Watertight, Query::Closest) => par_trace(pool, rays, hits, |r| t.closest::<true, COUNT>(r)),
            (Variant::Watertight, Query::Any) => par_trace(pool, rays, hits, |r| t.any::<true, COUNT>(r)),
        }
    }
}

impl<P: PeerTree> BenchTarget for PeerTarget<P> {
    fn name(&self) -> &str {
        &self.name
    }

    fn kind(&self) -> TargetKind {
        match self.variant {
            Variant::Own => TargetKind::PeerOwnTest,
            Variant::Watertight => TargetKind::PeerWatertight,
        }
    }

    fn trace(&self, pool: &rayon::ThreadPool, rays: &[Ray], query: Query, hits: &mut [Hit]) -> Result<(), String> {
        self.run::<false>(pool, rays, query, hits).map(|_| ())
    }

    fn work(&self, pool: &rayon::ThreadPool, rays: &[Ray], query: Query) -> Result<Option<Work>, String> {
        let mut hits = vec![Hit::MISS; rays.len()];
        let tests = self.run::<true>(pool, rays, query, &mut hits)?;
        Ok(Some(P::work(tests as f64 / rays.len().max(1) as f64)))
    }
}

/// Traces every ray with `one` (returning its hit and the triangle tests it made) in chunks of
/// [`CHUNK`] rays over `pool`; returns the total number of tests.
fn par_trace<F>(pool: &rayon::ThreadPool, rays: &[Ray], hits: &mut [Hit], one: F) -> Result<u64, String>
where
    F: Fn(&Ray) -> (Hit, u64) + Sync,
{
    if rays.len() != hits.len() {
        return Err(format!("{} rays but {} hit slots", rays.len(), hits.len()));
    }
    Ok(pool.install(|| {
        rays.par_chunks(CHUNK)
            .zip(hits.par_chunks_mut(CHUNK))
            .map(|(rs, hs)| {
                let mut tests = 0;
                for (r, h) in rs.iter().zip(hs) {
                    // As in raytrail: untraceable rays (NaN, zero direction, ...) are a miss.
                    let (hit, n) = if r.is_traceable() { one(r) } else { (Hit::MISS, 0) };
                    *h = hit;
                    tests += n;
                }
                tests
            })
            .sum()
    }))
}
