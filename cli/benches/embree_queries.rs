//! Criterion bench of refit and the nearest point against Embree's own (`--features embree`).
//!
//! `cargo bench -p raytrail-cli --features embree --bench embree_queries` times, side by side in
//! one process:
//! - `refit/<scene>`: a new frame of the conformance suite's [`breathing`] move (one phase per
//!   iteration in turn) taken by `raytrail` ([`CpuBackend::refit`] of the default tracer's parts,
//!   [`AUTO_WALKS`], on rayon's pool), by `embree-refit` (the vertices written into Embree's buffer, the
//!   geometry at `RTC_BUILD_QUALITY_REFIT` in a dynamic scene at low quality, `rtcCommitScene`)
//!   and by `embree-rebuild` (the same at Embree's default quality, which builds the tree again). Scenes: the sphereflake, the
//!   dragon and Sponza, as the `refit` bench of the `raytrail` crate.
//! - `nearest/<scene>`: the nearest point on the mesh to 16,384 points uniform in the scene's box
//!   grown by a quarter on each side, by `raytrail` ([`Tracer::nearest_points`]) and by `embree`
//!   (`rtcPointQuery` a point, its callback the same point-on-triangle function as raytrail's
//!   leaves, the radius shrunk to each nearer triangle), on the same rayon pool. Scenes: the
//!   sphereflake, the bunny and Sponza, as the `queries` bench.
//!
//! Embree's device gets as many build threads as rayon's pool (`RAYON_NUM_THREADS`). Before
//! timing, both nearest-point answers are compared: the distances must agree to 1e-5 of the
//! scene's size.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode, Throughput};
use embree3::{
    BufferUsage, BuildQuality, Config, Device, PointQuery, PointQueryContext, Scene as EmbreeScene, SceneFlags,
};
use rayon::prelude::*;
use raytrail::core::nearest::closest_point_on_triangle;
use raytrail::core::prepared::PreparedScene;
use raytrail::core::scene::Scene;
use raytrail::cpu::CpuBackend;
use raytrail::{Builder, TracerBuilder, AUTO_WALKS};
use raytrail_cli::embree_mesh::{triangle_geometry, write_vertices};
use raytrail_conformance::paths::{find_mesh, load_mesh_scene};
use raytrail_conformance::rays::query_points;
use raytrail_conformance::scenes::{breathing, sphereflake};
use std::time::Duration;

/// Phases of the frames the refit benches cycle through (the `refit` bench's).
const PHASES: [f32; 4] = [0.4, 1.1, 1.9, 2.6];

/// The sphereflake and those of `files` found in `../shared/scenes` (or `RAYTRAIL_SCENES`).
fn scenes(files: &[&str]) -> Vec<(String, Scene)> {
    let mut out = vec![("sphereflake".to_string(), sphereflake(3))];
    for &file in files {
        if find_mesh(file).is_some() {
            match load_mesh_scene(file) {
                Ok(s) => out.push((s.name, s.scene)),
                Err(e) => eprintln!("embree_queries bench: {file} does not load: {e}"),
            }
        }
    }
    out
}

/// An Embree scene of one triangle geometry at `quality`, each triangle with its own three
/// vertices (so Embree's primitive id is raytrail's), and the geometry's id.
fn embree_scene(device: &Device, scene: &Scene, quality: BuildQuality) -> (EmbreeScene<'static>, u32) {
    let mut geometry = triangle_geometry(device, scene).expect("an Embree geometry");
    geometry.set_build_quality(quality);
    let geometry = geometry.commit();
    let mut embree = device.create_scene().expect("an Embree scene");
    if quality == BuildQuality::REFIT {
        // Embree honours a geometry's refit quality in its two-level mode (a tree per mesh under
        // a top-level tree), which a scene at low build quality selects; otherwise a scene of
        // one mesh is built as one tree at the scene's quality, refit or not.
        embree.set_flags(SceneFlags::DYNAMIC);
        embree.set_build_quality(BuildQuality::LOW);
    }
    let id = embree.attach_geometry(&geometry);
    embree.commit();
    (embree, id)
}

/// Embree takes a new frame: the vertices written into its buffer, marked updated, and the scene
/// committed (a refit or a rebuild, by the geometry's build quality).
fn embree_frame(embree: &mut EmbreeScene<'static>, id: u32, frame: &Scene) {
    embree
        .with_geometry_buffer_mut::<[f32; 3], _>(id, BufferUsage::VERTEX, 0, |v| write_vertices(v, frame))
        .expect("the vertex buffer");
    embree.update_geometry_buffer(id, BufferUsage::VERTEX, 0);
    embree.commit_geometry(id);
    embree.commit();
}

fn device() -> Device {
    let threads = u32::try_from(rayon::current_num_threads()).unwrap_or(0);
    Device::with_config(Config { threads, ..Config::default() }).expect("an Embree device")
}

fn refit(c: &mut Criterion) {
    let device = device();
    for (name, scene) in scenes(&["dragon_vrip.ply.gz", "sponza.obj"]) {
        let frames: Vec<Scene> = PHASES.iter().map(|&p| breathing(&scene, p).expect("a moved scene")).collect();
        let mut group = c.benchmark_group(format!("refit/{name}"));
        group.sampling_mode(SamplingMode::Flat).sample_size(10).measurement_time(Duration::from_secs(8));
        let bvh = Builder::Best.build(&scene).expect("build");
        let mut prepared = PreparedScene::new(&scene, bvh, &AUTO_WALKS).expect("prepare");
        let backend = CpuBackend::new();
        group.bench_function(BenchmarkId::from_parameter("raytrail"), |b| {
            let mut k = 0;
            b.iter(|| {
                k = (k + 1) % frames.len();
                backend.refit(&mut prepared, &frames[k]).expect("refit");
            })
        });
        for (peer, quality) in [("embree-refit", BuildQuality::REFIT), ("embree-rebuild", BuildQuality::MEDIUM)] {
            let (mut embree, id) = embree_scene(&device, &scene, quality);
            group.bench_function(BenchmarkId::from_parameter(peer), |b| {
                let mut k = 0;
                b.iter(|| {
                    k = (k + 1) % frames.len();
                    embree_frame(&mut embree, id, &frames[k]);
                })
            });
        }
        group.finish();
    }
}

/// The distance from `p` to the nearest triangle of `embree` (`rtcPointQuery`), `INFINITY` for
/// an empty scene.
fn embree_nearest(embree: &EmbreeScene<'static>, scene: &Scene, p: [f32; 3]) -> f32 {
    let mut query = PointQuery { x: p[0], y: p[1], z: p[2], time: 0.0, radius: f32::INFINITY };
    let mut context = PointQueryContext::default();
    let mut best = f32::INFINITY;
    let tris = scene.triangles();
    let point = glam::Vec3::from_array(p);
    embree.point_query(&mut query, &mut context, |q, _, prim, _, _| {
        let [a, b, c] = tris[prim as usize].v;
        let d = closest_point_on_triangle(point, a, b, c).distance2.sqrt();
        if d < q.radius {
            q.radius = d;
            best = d;
            return true;
        }
        false
    });
    best
}

fn nearest(c: &mut Criterion) {
    let device = device();
    for (name, scene) in scenes(&["bunny.obj", "sponza.obj"]) {
        let tracer = TracerBuilder::default().build_scene(&scene).expect("tracer");
        let (embree, _) = embree_scene(&device, &scene, BuildQuality::MEDIUM);
        let pts = query_points(&scene, 1 << 14, 0.25, 3);
        let ours = tracer.nearest_points(&pts, f32::INFINITY).expect("nearest");
        let size = scene.bounds().max_abs();
        for (p, n) in pts.iter().zip(&ours) {
            let theirs = embree_nearest(&embree, &scene, *p);
            let d = n.map_or(f32::INFINITY, |n| n.distance);
            assert!((d - theirs).abs() <= 1e-5 * size, "{name} {p:?}: raytrail {d}, embree {theirs}");
        }
        let mut group = c.benchmark_group(format!("nearest/{name}"));
        group.sampling_mode(SamplingMode::Flat).sample_size(10).measurement_time(Duration::from_secs(5));
        group.throughput(Throughput::Elements(pts.len() as u64));
        group.bench_function(BenchmarkId::from_parameter("raytrail"), |b| {
            b.iter(|| tracer.nearest_points(&pts, f32::INFINITY).expect("nearest").len())
        });
        group.bench_function(BenchmarkId::from_parameter("embree"), |b| {
            b.iter(|| pts.par_iter().map(|p| embree_nearest(&embree, &scene, *p)).filter(|d| d.is_finite()).count())
        });
        group.finish();
    }
}

criterion_group!(benches, refit, nearest);
criterion_main!(benches);
