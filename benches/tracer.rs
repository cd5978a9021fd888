//! Criterion bench of [`Tracer`]'s repeated calls with `auto` (the default) against the method
//! `auto` picks, named up front.
//!
//! `cargo bench --bench tracer` times, per scene (the sphereflake, generated; Sponza from
//! `../shared/scenes` or `RAYTRAIL_SCENES`, left out when absent) and batch (512 x 512 camera rays
//! and the diffuse bounces of their hits), one [`Tracer::intersect_into`] call after another:
//! - `auto`: a tracer that picks its method per kind of batch, keeping the choice for later calls
//!   of the kind (`raytrail::analysis::plans`);
//! - `fixed`: a tracer built for the method `auto` picked for that batch, which pays
//!   nothing for choosing: the floor `auto` is held to.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode, Throughput};
use raytrail::core::scene::Scene;
use raytrail::core::Hit;
use raytrail::{Tracer, TracerBuilder};
use raytrail_conformance::paths::{find_mesh, load_mesh_scene};
use raytrail_conformance::rays::{diffuse, primary, RAY_SEED};
use raytrail_conformance::scenes::sphereflake;
use std::time::Duration;

fn scenes() -> Vec<(String, Scene)> {
    let mut out = vec![("sphereflake".to_string(), sphereflake(3))];
    if find_mesh("sponza.obj").is_some() {
        if let Ok(s) = load_mesh_scene("sponza.obj") {
            out.push((s.name, s.scene));
        }
    }
    out
}

fn tracer(c: &mut Criterion) {
    for (name, scene) in scenes() {
        let auto = TracerBuilder::default().build_scene(&scene).expect("tracer");
        let camera = primary(&scene, 512, 512);
        let camera_hits = auto.intersect(&camera).expect("trace");
        let bounces = diffuse(&camera, &camera_hits, &scene, RAY_SEED);
        let mut group = c.benchmark_group(format!("tracer/{name}"));
        group.sampling_mode(SamplingMode::Flat).sample_size(20).measurement_time(Duration::from_secs(5));
        for (batch, rays) in [("camera", &camera), ("diffuse", &bounces)] {
            group.throughput(Throughput::Elements(rays.len() as u64));
            let mut hits = vec![Hit::MISS; rays.len()];
            let method = auto.method_for(rays, raytrail::core::method::Query::Closest).expect("choice");
            let fixed: Tracer = TracerBuilder::default().method(method).build_scene(&scene).expect("tracer");
            group.bench_function(BenchmarkId::new("auto", batch), |b| {
                b.iter(|| auto.intersect_into(rays, &mut hits).expect("trace"))
            });
            group.bench_function(BenchmarkId::new(format!("fixed {}", method.name()), batch), |b| {
                b.iter(|| fixed.intersect_into(rays, &mut hits).expect("trace"))
            });
        }
        group.finish();
    }
}

criterion_group!(benches, tracer);
criterion_main!(benches);
