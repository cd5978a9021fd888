//! A scene prepared for the method a command was given, or for the one `--method auto` picks on
//! the command's own rays: what `trace` and `render` share.

use crate::progress::timed;
use raytrail::core::bvh2::Bvh2;
use raytrail::core::method::{Bvh2Method, Method, Query};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::scene::Scene;
use raytrail::core::Ray;
use raytrail::cpu::CpuBackend;

/// The scene prepared for `method`, or, for `None` (auto), for the candidate that traces a sample
/// of `rays` fastest with `query` on `backend` (the choice printed on stderr); with the method.
pub fn prepare_for(
    scene: &Scene,
    bvh: Bvh2,
    method: Option<Method>,
    rays: &[Ray],
    query: Query,
    backend: &CpuBackend,
) -> Result<(PreparedScene, Method), String> {
    let fixed = |m: Method, bvh: Bvh2| {
        let (prepared, _) = timed("deriving the method's layouts", || PreparedScene::new(scene, bvh, &[m]));
        Ok((prepared.map_err(|e| e.to_string())?, m))
    };
    match method {
        Some(m) => fixed(m, bvh),
        // Nothing to sample: any method traces no rays alike; the cheapest to prepare.
        None if rays.is_empty() => fixed(Method::Bvh2(Bvh2Method::Stack), bvh),
        None => {
            let (candidates, _) = timed("preparing the candidates of --method auto", || {
                raytrail::analysis::prepare_candidates(scene, bvh)
            });
            let (chosen, _) = timed("choosing on a sample of the rays", || {
                raytrail::analysis::choose_and_keep(backend, candidates.map_err(|e| e.to_string())?, rays, query)
                    .map_err(|e| e.to_string())
            });
            let (prepared, choice) = chosen?;
            errln!(
                "auto: {} (of {}; {} sample rays, {:.2} ms)",
                choice.method,
                choice.timed.iter().map(|t| t.method.name()).collect::<Vec<_>>().join(", "),
                raytrail::analysis::sample::sample_size(rays.len()),
                1e3 * choice.cost_seconds
            );
            Ok((prepared, choice.method))
        }
    }
}
