//! The main job's table of the queries beyond closest and any hit: every hit along the camera
//! rays, the nearest point to points around the scene, and a refit after the vertices move, each
//! timed and checked (the lists and points bit for bit against a brute force over every triangle
//! on a sample, and the GPU's, where there is one, against the CPU's; the refit's closest hits
//! against a scene prepared afresh).

use crate::gpu::Gpu;
use raytrail::core::method::{Bvh2Method, Method};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::scene::Scene;
use raytrail::core::trace::{Trace, TraceOptions};
use raytrail::core::{Hit, Ray};
use raytrail::cpu::CpuBackend;
use raytrail::{AllHitsOptions, Builder, Instance, InstancedTracer, TracerBuilder, Transform};
use raytrail_conformance::all_hits::brute_force_mismatches;
use raytrail_conformance::instanced::{closest_disagreements, flatten};
use raytrail_conformance::rays::{primary, query_points};
use raytrail_conformance::scenes::breathing;
use std::sync::Arc;
use std::time::Instant;

/// Rays and points checked against a brute force over every triangle (the dragon has 871k).
const SAMPLE: usize = 64;

/// Prints the table; returns how many checks failed.
pub fn print_queries(
    backend: &CpuBackend,
    gpu: Option<&Gpu>,
    prepared: &Arc<PreparedScene>,
    scene: &Scene,
    builder: Builder,
    camera: &[Ray],
) -> Result<usize, String> {
    let cpu = backend.prepare(prepared.clone()).map_err(|e| e.to_string())?;
    let mut failed = 0;
    outln!("\nqueries beyond closest and any hit (the 8-wide tree of least node area):");

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
    if let Some((on_gpu, s)) = gpu.and_then(|g| on_the_gpu(g.all_hits(camera, &AllHitsOptions::default()), &mut failed))
    {
        let differ = (0..camera.len())
            .filter(|&i| {
                let bits = |l: Option<&[Hit]>| {
                    l.unwrap_or(&[])
                        .iter()
                        .map(|h| (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits()))
                        .collect::<Vec<_>>()
                };
                bits(on_gpu.ray(i)) != bits(lists.ray(i)) || on_gpu.is_truncated(i) != lists.is_truncated(i)
            })
            .count();
        failed += differ;
        outln!(
            "    on the GPU{:>8.2} Mrays/s end to end; {differ} of {} lists differ from the CPU's",
            camera.len() as f64 / s.max(1e-9) / 1e6,
            camera.len()
        );
    }

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
    if let Some((on_gpu, s)) = gpu.and_then(|g| on_the_gpu(g.nearest_points(&points, f32::INFINITY), &mut failed)) {
        let differ = on_gpu.iter().zip(&found).filter(|(a, b)| a != b).count();
        failed += differ;
        outln!(
            "    on the GPU{:>8.2} M points/s end to end; {differ} of {} answers differ from the CPU's",
            points.len() as f64 / s.max(1e-9) / 1e6,
            points.len()
        );
    }

    failed += print_instances(scene).unwrap_or_else(|e| {
        outln!("  instances   FAILED: {e}");
        1
    });

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

/// The instances row: the scene placed four times (as it is; moved along x; turned a quarter
/// about y and moved along z; halved and moved the other way along x), camera rays framing all
/// four traced through the instances and through the same triangles flattened, each timed; a
/// sample of the instanced hits judged against the exact answer of the flattened triangles (an
/// instanced ray is mapped into the mesh's frame, so bit-identity with the flat scene is not the
/// rule). Returns how many sampled rays disagree.
fn print_instances(scene: &Scene) -> Result<usize, String> {
    let s = (scene.bounds().max - scene.bounds().min).max_element();
    let (q, h) = (1.5 * s, 0.5);
    let instances: Vec<Instance> = [
        [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]],
        [[1.0, 0.0, 0.0, q], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]],
        [[0.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [-1.0, 0.0, 0.0, q]],
        [[h, 0.0, 0.0, -q], [0.0, h, 0.0, 0.0], [0.0, 0.0, h, 0.0]],
    ]
    .into_iter()
    .enumerate()
    .map(|(i, rows)| Instance { id: i as u32, ..Instance::new(0, Transform::from_rows(rows)) })
    .collect();
    let meshes = std::slice::from_ref(scene);
    let instanced = InstancedTracer::new(meshes, &instances).map_err(|e| e.to_string())?;
    let (flat, first) = flatten(meshes, &instances, None);
    let flat_scene = Scene::new(flat.clone()).map_err(|e| e.to_string())?;
    let flattened = TracerBuilder::default().build_scene(&flat_scene).map_err(|e| e.to_string())?;
    let rays = primary(&flat_scene, 320, 240);
    let timed = |f: &dyn Fn() -> Result<usize, raytrail::Error>| -> Result<f64, String> {
        f().map_err(|e| e.to_string())?;
        let start = Instant::now();
        f().map_err(|e| e.to_string())?;
        Ok(rays.len() as f64 / start.elapsed().as_secs_f64().max(1e-9) / 1e6)
    };
    let instanced_speed = timed(&|| instanced.intersect(&rays).map(|h| h.len()))?;
    let flat_speed = timed(&|| flattened.intersect(&rays).map(|h| h.len()))?;
    let step = rays.len().div_ceil(SAMPLE).max(1);
    let sample: Vec<Ray> = rays.iter().step_by(step).copied().collect();
    let hits = instanced.intersect(&sample).map_err(|e| e.to_string())?;
    let wrong = closest_disagreements(&flat, &first, &instances, &sample, &hits).len();
    outln!(
        "  instances   {instanced_speed:>8.2} Mrays/s  (the scene placed 4 times, {:.2} Mrays/s flattened); {wrong} of {} \
         sampled camera rays disagree with the exact answer",
        flat_speed,
        sample.len()
    );
    Ok(wrong)
}

/// A GPU query's answer, or `None` with its error printed on the row and counted in `failed`: a
/// device that fails a query is a failed check of the table, not the end of the run.
fn on_the_gpu<T>(answer: Result<T, String>, failed: &mut usize) -> Option<T> {
    answer
        .map_err(|e| {
            outln!("    on the GPU FAILED: {e}");
            *failed += 1;
        })
        .ok()
}
