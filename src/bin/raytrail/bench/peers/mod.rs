//! Peer libraries traced on the same rays, in the same process, on the same thread pool.
//!
//! Each peer is built with its own builder and traced twice: with its own triangle test, and with
//! raytrail's watertight test (prepared once per ray, called per triangle) in its closest-hit or
//! any-hit callback, so that differences from the triangle test and from the traversal are told
//! apart. The watertight variants also keep raytrail's closest-hit tie rule (equal `t`: smaller
//! primitive id) and its inclusive interval, so their hits can match raytrail's bit for bit.

mod bvh_crate;
mod obvhs;

use super::report::Built;
use super::target::Targets;
use rayon::prelude::*;
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
        match name.as_str() {
            "obvhs-bvh2" => {
                let (tree, b) = pool.install(|| obvhs::ObvhsScene::bvh2(scene));
                let tree = Arc::new(tree);
                targets.push(Box::new(obvhs::ObvhsTarget::new(name, tree.clone(), Variant::Own)));
                targets.push(Box::new(obvhs::ObvhsTarget::new(name, tree, Variant::Watertight)));
                built.push(b);
            }
            "obvhs-cwbvh" => {
                let (tree, b) = pool.install(|| obvhs::ObvhsScene::cwbvh(scene));
                let tree = Arc::new(tree);
                targets.push(Box::new(obvhs::ObvhsTarget::new(name, tree.clone(), Variant::Own)));
                targets.push(Box::new(obvhs::ObvhsTarget::new(name, tree, Variant::Watertight)));
                built.push(b);
            }
            "bvh" => {
                let (tree, b) = pool.install(|| bvh_crate::BvhScene::new(scene));
                let tree = Arc::new(tree);
                targets.push(Box::new(bvh_crate::BvhTarget::new(name, tree.clone(), Variant::Own)));
                targets.push(Box::new(bvh_crate::BvhTarget::new(name, tree, Variant::Watertight)));
                built.push(b);
            }
            other => return Err(format!("unknown peer '{other}'")),
        }
    }
    Ok((targets, built))
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
