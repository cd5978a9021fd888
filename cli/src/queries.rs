//! The main job's table of the queries beyond closest and any hit: every hit along the camera
//! rays, the nearest point to points around the scene, and a refit after the vertices move, each
//! timed and checked (the lists and points bit for bit against a brute force over every triangle
//! on a sample; the refit's closest hits against a scene prepared afresh).

use raytrail::core::method::{Bvh2Method, Method};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::scene::Scene;
use raytrail::core::trace::{Trace, TraceOptions};
use raytrail::core::{Hit, Ray};
use raytrail::cpu::CpuBackend;
use raytrail::{AllHitsOptions, Builder};
use raytrail_conformance::all_hits::brute_force_mismatches;
use raytrail_conformance::rays::query_points;
use raytrail_conformance::scenes::breathing;
use std::sync::Arc;
use std::time::Instant;

/// Rays and points checked against a brute force over every triangle (the dragon has 871k).
const SAMPLE: usize = 64;

/// Prints the table; returns how many checks failed.
pub fn print_queries(
    backend: &CpuBackend,
    prepared: &Arc<PreparedScene>,
    scene: &Scene,
    builder: Builder,
    camera: &[Ray],
) -> Result<usize, String> {
    let cpu = backend.prepare(prepared.clone()).map_err(|e| e.to_string())?;
    let mut failed = 0;
    outln!("\nqueries beyond closest and any hit (CPU, the 8-wide tree of least node area):");

    let start = Instant::now();
    let lists = backend.all_hits(&cpu, camera, &AllHitsOptions::default()).map_err(|e| e.to_string())?;
    let s = start.elapsed().as_secs_f64();
    let step = camera.len().div_ceil(SAMPLE).max(1);
    let sample: Vec<Ray> = camera.iter().step_by(step).copied().collect();
    let sampled = backend.all_hits(&cpu, &sample, &AllHitsOptions::default()).map_err(|e| e.to_string())?;
    let wrong = brute_force_mismatches(prepared, &sample, &AllHitsOptions::default(), &sampled).len();
    failed += wrong;
    outln!(
        "  all hits    {:>8.2} Mrays/s  {:.2} hits per camera ray; {} of {} sampled lists differ from a brute force",
        camera.len() as f64 / s.max(1e-9) / 1e6,
        lists.hits().len() as f64 / camera.len().max(1) as f64,
        wrong,
        sample.len()
    );

    let points = query_points(scene, 1 << 14, 0.25, 7);
    let start = Instant::now();
    let found = backend.nearest_points(&cpu, &points, f32::INFINITY).map_err(|e| e.to_string())?;
    let s = start.elapsed().as_secs_f64();
    let wrong = points
        .iter()
        .zip(&found)
        .step_by(points.len() / SAMPLE)
        .filter(|(p, f)| **f != raytrail_conformance::nearest::brute_force(scene, **p, f32::INFINITY))
        .count();
    failed += wrong;
    outln!(
        "  nearest     {:>8.2} M points/s  ({} points around the scene); {} of {SAMPLE} sampled differ from a brute force",
        points.len() as f64 / s.max(1e-9) / 1e6,
        points.len(),
        wrong
    );

    let moved = breathing(scene, 1.3).map_err(|e| e.to_string())?;
    let mut refitted = (**prepared).clone();
    let start = Instant::now();
    refitted.refit(&moved).map_err(|e| e.to_string())?;
    let refit_s = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let bvh = builder.build(&moved).map_err(|e| e.to_string())?;
    let fresh = PreparedScene::new(&moved, bvh, &Method::ALL).map_err(|e| e.to_string())?;
    let rebuild_s = start.elapsed().as_secs_f64();
    let stack = TraceOptions::new(Method::Bvh2(Bvh2Method::Stack));
    let trace = |p: PreparedScene| -> Result<Vec<Hit>, String> {
        let s = backend.prepare(Arc::new(p)).map_err(|e| e.to_string())?;
        let mut hits = vec![Hit::MISS; camera.len()];
        backend.trace(&s, camera, &stack, &mut hits).map_err(|e| e.to_string())?;
        Ok(hits)
    };
    let (a, b) = (trace(refitted)?, trace(fresh)?);
    let wrong = a.iter().zip(&b).filter(|(x, y)| !x.same_as(y)).count();
    failed += wrong;
    outln!(
        "  refit       {:>8.1} ms for every method's parts after the vertices moved, against {:.1} ms to build and \
         prepare again; {} of {} camera rays' hits differ from the rebuilt scene's",
        1e3 * refit_s,
        1e3 * rebuild_s,
        wrong,
        camera.len()
    );
    Ok(failed)
}
