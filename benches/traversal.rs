//! Criterion bench of the BVH2 methods a-d and the five kd-tree methods on real scenes.
//!
//! `cargo bench --bench traversal` traces the same primary and diffuse rays with every method on
//! the CPU backend (all threads) and reports time per batch; compare methods side by side within
//! one run. Scenes come from `../shared/scenes` (or `RAYTRAIL_SCENES`).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use raytrail::core::method::{Bvh2Method, KdMethod, Method};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::trace::{Trace, TraceOptions};
use raytrail::core::Hit;
use raytrail::cpu::CpuBackend;
use raytrail::Builder;
use raytrail_conformance::paths::load_mesh_scene;
use raytrail_conformance::rays::{diffuse, primary, RAY_SEED};
use std::sync::Arc;

const SCENES: &[&str] = &["bunny.obj", "sponza.obj"];
const METHODS: &[Method] = &[
    Method::Bvh2(Bvh2Method::Stack),
    Method::Bvh2(Bvh2Method::ParentSibling),
    Method::Bvh2(Bvh2Method::Uncle),
    Method::Bvh2(Bvh2Method::Hash),
    Method::Kd(KdMethod::Stack),
    Method::Kd(KdMethod::Restart),
    Method::Kd(KdMethod::PushDown),
    Method::Kd(KdMethod::ShortStack),
    Method::Kd(KdMethod::Packet),
];

fn bench(c: &mut Criterion) {
    let backend = CpuBackend::new();
    for file in SCENES {
        let named = match load_mesh_scene(file) {
            Ok(s) => s,
            Err(e) => panic!("{e} (the bench reads ../shared/scenes or RAYTRAIL_SCENES)"),
        };
        let bvh = Builder::Sah.build(&named.scene).expect("build");
        let prepared = PreparedScene::new(&named.scene, bvh, METHODS).expect("prepare");
        let scene = backend.prepare(Arc::new(prepared)).expect("prepare");
        let prim = primary(&named.scene, 256, 192);
        let mut hits = vec![Hit::MISS; prim.len()];
        backend.trace(&scene, &prim, &TraceOptions::new(Method::Bvh2(Bvh2Method::Stack)), &mut hits).expect("trace");
        let bounce = diffuse(&prim, &hits, &named.scene, RAY_SEED);
        for (kind, rays) in [("primary", &prim), ("diffuse", &bounce)] {
            let mut group = c.benchmark_group(format!("{}/{kind}", named.name));
            group.throughput(Throughput::Elements(rays.len() as u64));
            group.sample_size(20);
            let mut out = vec![Hit::MISS; rays.len()];
            for &method in METHODS {
                group.bench_with_input(BenchmarkId::from_parameter(method.name()), rays, |b, rays| {
                    b.iter(|| backend.trace(&scene, rays, &TraceOptions::new(method), &mut out).expect("trace"))
                });
            }
            group.finish();
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
