//! Criterion bench of instanced scenes against the same triangles flattened into one mesh.
//!
//! `cargo bench --bench instances` places a mesh many times on a grid (each copy turned and
//! scaled its own way): 64 sphereflakes of depth 2 (generated), and 16 bunnies where
//! `../shared/scenes` (or `RAYTRAIL_SCENES`) has the bunny. Per scene, on the tracer's threads:
//! - the build of the instanced scene ([`raytrail::InstancedTracer`]: each mesh's tree once, the
//!   top level over the copies) against the build of the flattened one (one tree over every
//!   copy's triangles);
//! - `camera` and `diffuse` rays (256 x 192 framing the whole grid, and one diffuse bounce from
//!   their hits), each traced by `instanced` and by `flattened`, both with the single-ray walk of
//!   the 8-wide tree of least node area ([`INSTANCED_DEFAULT`]).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode, Throughput};
use raytrail::core::glam::{Affine3A, EulerRot, Quat, Vec3};
use raytrail::core::scene::Scene;
use raytrail::{Instance, TracerBuilder, Transform, INSTANCED_DEFAULT};
use raytrail_conformance::instanced::flatten;
use raytrail_conformance::paths::{find_mesh, load_mesh_scene};
use raytrail_conformance::rays::{diffuse, primary};
use raytrail_conformance::scenes::sphereflake;
use std::time::Duration;

/// `side` x `side` copies of mesh 0 (whose box is `bounds_size` across) on a grid in the xz
/// plane, each turned about y and tilted, and scaled by 0.6-1.4.
fn grid(side: u32, bounds_size: f32) -> Vec<Instance> {
    let mut out = Vec::new();
    for i in 0..side * side {
        let (x, z) = ((i % side) as f32, (i / side) as f32);
        let k = i as f32;
        let scale = 0.6 + 0.8 * ((k * 0.618).fract());
        let turn = Quat::from_euler(EulerRot::YXZ, k * 1.3, 0.2 * (k * 0.7).sin(), 0.0);
        let at = Vec3::new(x, 0.0, z) * 1.6 * bounds_size;
        let map = Affine3A::from_scale_rotation_translation(Vec3::splat(scale), turn, at);
        out.push(Instance::new(0, Transform::from_affine(map)).with_id(i));
    }
    out
}

fn cases() -> Vec<(String, Scene, Vec<Instance>)> {
    let flake = sphereflake(2);
    let size = (flake.bounds().max - flake.bounds().min).max_element();
    let mut out =
        vec![(format!("sphereflake2-x64 ({} triangles each)", flake.triangles().len()), flake, grid(8, size))];
    if find_mesh("bunny.obj").is_some() {
        if let Ok(s) = load_mesh_scene("bunny.obj") {
            let size = (s.scene.bounds().max - s.scene.bounds().min).max_element();
            out.push((format!("bunny-x16 ({} triangles each)", s.scene.triangles().len()), s.scene, grid(4, size)));
        }
    }
    out
}

fn instances(c: &mut Criterion) {
    for (name, mesh, placements) in cases() {
        let meshes = [mesh];
        let flat = Scene::new(flatten(&meshes, &placements, None).0).expect("flattened scene");
        let short = name.split(' ').next().unwrap_or(&name).to_string();
        let builder = TracerBuilder::default().method(INSTANCED_DEFAULT);

        let mut group = c.benchmark_group(format!("instances-build/{short}"));
        group.sampling_mode(SamplingMode::Flat).sample_size(10).measurement_time(Duration::from_secs(5));
        group.bench_function(BenchmarkId::from_parameter("instanced"), |b| {
            b.iter(|| builder.build_instanced(&meshes, &placements).expect("instanced").instances().len())
        });
        group.bench_function(BenchmarkId::from_parameter("flattened"), |b| {
            b.iter(|| builder.build_scene(&flat).expect("flattened").triangle_count())
        });
        group.finish();

        let instanced = builder.build_instanced(&meshes, &placements).expect("instanced");
        let flattened = builder.build_scene(&flat).expect("flattened");
        let camera = primary(&flat, 256, 192);
        let camera_hits = flattened.intersect(&camera).expect("camera hits");
        let bounce = diffuse(&camera, &camera_hits, &flat, 7);
        for (kind, rays) in [("camera", &camera), ("diffuse", &bounce)] {
            let mut group = c.benchmark_group(format!("instances-{kind}/{short}"));
            group.sampling_mode(SamplingMode::Flat).sample_size(10).measurement_time(Duration::from_secs(5));
            group.throughput(Throughput::Elements(rays.len() as u64));
            group.bench_function(BenchmarkId::from_parameter("instanced"), |b| {
                b.iter(|| instanced.intersect(rays).expect("instanced").iter().filter(|h| h.is_hit()).count())
            });
            group.bench_function(BenchmarkId::from_parameter("flattened"), |b| {
                b.iter(|| flattened.intersect(rays).expect("flattened").iter().filter(|h| h.is_hit()).count())
            });
            group.finish();
        }
        eprintln!("{name}: {} copies, {} triangles flattened", placements.len(), flat.triangles().len());
    }
}

criterion_group!(benches, instances);
criterion_main!(benches);
