//! Criterion bench of refitting against building again, for scenes whose vertices move.
//!
//! `cargo bench --bench refit` times, per scene, what a new frame of an animation costs the
//! default tracer's scene ([`AUTO_WALKS`]: the canonical BVH2 and its 8-wide tree of least node
//! area) and a scene prepared for every method:
//! - `rebuild`: [`Builder::Best`] on the moved triangles, then [`PreparedScene::new`];
//! - `refit`: [`CpuBackend::refit`] of the scene built for the first frame, on rayon's pool.
//!
//! The frames are the scene's vertices moved by the conformance suite's [`breathing`] (every
//! vertex pushed from or pulled to the centre by a factor that varies along x), one phase per
//! iteration in turn. Scenes: the sphereflake (generated, always there) and the dragon and Sponza
//! from `../shared/scenes` (or `RAYTRAIL_SCENES`), left out when absent. The builders run on
//! rayon's pool as the tracer's do (`RAYON_NUM_THREADS` fixes its size), and so does the refit.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode};
use raytrail::core::method::Method;
use raytrail::core::prepared::PreparedScene;
use raytrail::core::scene::Scene;
use raytrail::cpu::CpuBackend;
use raytrail::{Builder, AUTO_WALKS};
use raytrail_conformance::paths::{find_mesh, load_mesh_scene};
use raytrail_conformance::scenes::{breathing, sphereflake};
use std::time::Duration;

/// Phases of the frames the benches cycle through.
const PHASES: [f32; 4] = [0.4, 1.1, 1.9, 2.6];

fn scenes() -> Vec<(String, Scene)> {
    let mut out = vec![("sphereflake".to_string(), sphereflake(3))];
    for file in ["dragon_vrip.ply.gz", "sponza.obj"] {
        if find_mesh(file).is_some() {
            match load_mesh_scene(file) {
                Ok(s) => out.push((s.name, s.scene)),
                Err(e) => eprintln!("refit bench: {file} does not load: {e}"),
            }
        }
    }
    out
}

fn refit_against_rebuild(c: &mut Criterion) {
    for (name, scene) in scenes() {
        let frames: Vec<Scene> = PHASES.iter().map(|&p| breathing(&scene, p).expect("a moved scene")).collect();
        let mut group = c.benchmark_group(format!("refit/{name}"));
        group.sampling_mode(SamplingMode::Flat).sample_size(10).measurement_time(Duration::from_secs(8));
        for (parts, methods) in [("tracer", &AUTO_WALKS[..]), ("all-methods", &Method::ALL[..])] {
            group.bench_function(BenchmarkId::new("rebuild", parts), |b| {
                let mut k = 0;
                b.iter(|| {
                    k = (k + 1) % frames.len();
                    let bvh = Builder::Best.build(&frames[k]).expect("build");
                    PreparedScene::new(&frames[k], bvh, methods).expect("prepare")
                })
            });
            let bvh = Builder::Best.build(&scene).expect("build");
            let mut prepared = PreparedScene::new(&scene, bvh, methods).expect("prepare");
            let backend = CpuBackend::new();
            group.bench_function(BenchmarkId::new("refit", parts), |b| {
                let mut k = 0;
                b.iter(|| {
                    k = (k + 1) % frames.len();
                    backend.refit(&mut prepared, &frames[k]).expect("refit");
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, refit_against_rebuild);
criterion_main!(benches);
