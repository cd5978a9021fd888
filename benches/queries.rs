//! Criterion bench of the queries beyond closest and any hit, against what a user would do
//! without them.
//!
//! `cargo bench --bench queries` times, per scene (the sphereflake, generated; the bunny and
//! Sponza from `../shared/scenes` or `RAYTRAIL_SCENES`, left out when absent), on the tracer's
//! threads:
//! - `all-hits`: [`Tracer::intersect_all`] of the camera rays, against `closest` (one
//!   [`Tracer::intersect`] of the same rays: the floor a list can cost) and `recast` (the
//!   closest hit, then the ray cast again from just past it until it leaves the scene: trimesh's
//!   `multiple_hits` loop, which also loses hits at equal `t`);
//! - `nearest`: [`Tracer::nearest_points`] of points in and around the scene's box, against
//!   `brute-force` over every triangle (on the sphereflake only: it is that slow).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode, Throughput};
use raytrail::core::scene::Scene;
use raytrail::{AllHitsOptions, Ray, Tracer, TracerBuilder};
use raytrail_conformance::nearest::brute_force;
use raytrail_conformance::paths::{find_mesh, load_mesh_scene};
use raytrail_conformance::rays::{primary, query_points};
use raytrail_conformance::scenes::sphereflake;
use std::time::Duration;

fn scenes() -> Vec<(String, Scene)> {
    let mut out = vec![("sphereflake".to_string(), sphereflake(3))];
    for file in ["bunny.obj", "sponza.obj"] {
        if find_mesh(file).is_some() {
            if let Ok(s) = load_mesh_scene(file) {
                out.push((s.name, s.scene));
            }
        }
    }
    out
}

/// Every hit by casting again past each closest hit, as trimesh's `multiple_hits` does.
fn recast(tracer: &Tracer, rays: &[Ray]) -> usize {
    let mut live: Vec<Ray> = rays.to_vec();
    let mut total = 0;
    while !live.is_empty() {
        let hits = tracer.intersect(&live).expect("trace");
        let mut next = Vec::with_capacity(live.len());
        for (r, h) in live.iter().zip(&hits) {
            if h.is_hit() {
                total += 1;
                // Just past the hit: the next float above its t.
                next.push(Ray { tmin: f32::from_bits(h.t.to_bits() + 1), ..*r });
            }
        }
        live = next;
    }
    total
}

fn queries(c: &mut Criterion) {
    for (name, scene) in scenes() {
        let tracer = TracerBuilder::default().build_scene(&scene).expect("tracer");
        let rays = primary(&scene, 256, 192);
        let mut group = c.benchmark_group(format!("all-hits/{name}"));
        group.sampling_mode(SamplingMode::Flat).sample_size(10).measurement_time(Duration::from_secs(5));
        group.throughput(Throughput::Elements(rays.len() as u64));
        let options = AllHitsOptions::default();
        group.bench_function(BenchmarkId::from_parameter("all-hits"), |b| {
            b.iter(|| tracer.intersect_all(&rays, &options).expect("all hits").hits().len())
        });
        group.bench_function(BenchmarkId::from_parameter("closest"), |b| {
            b.iter(|| tracer.intersect(&rays).expect("closest").iter().filter(|h| h.is_hit()).count())
        });
        group.bench_function(BenchmarkId::from_parameter("recast"), |b| b.iter(|| recast(&tracer, &rays)));
        group.finish();

        let pts = query_points(&scene, 1 << 14, 0.25, 3);
        let mut group = c.benchmark_group(format!("nearest/{name}"));
        group.sampling_mode(SamplingMode::Flat).sample_size(10).measurement_time(Duration::from_secs(5));
        group.throughput(Throughput::Elements(pts.len() as u64));
        group.bench_function(BenchmarkId::from_parameter("nearest"), |b| {
            b.iter(|| tracer.nearest_points(&pts, f32::INFINITY).expect("nearest").len())
        });
        if name == "sphereflake" {
            let few = &pts[..256];
            group.throughput(Throughput::Elements(few.len() as u64));
            group.bench_function(BenchmarkId::from_parameter("brute-force"), |b| {
                b.iter(|| few.iter().filter_map(|p| brute_force(&scene, *p, f32::INFINITY)).count())
            });
        }
        group.finish();
    }
}

criterion_group!(benches, queries);
criterion_main!(benches);
