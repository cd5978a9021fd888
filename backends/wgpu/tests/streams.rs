//! The ways a trace can be spread over the device give the same answers, and the device state a
//! scene keeps is reused:
//! - tracing again allocates no buffer; a larger trace grows them once;
//! - streams of small batches with several in flight, persistent threads and other workgroup sizes
//!   give every method's hits and counters bit for bit as one-batch grid dispatch does;
//! - kernel timing returns its samples and the end-to-end report its transfer bytes.
//!
//! (The conformance suite runs in full on a streamed, persistent-thread configuration in
//! `conformance_persistent.rs`.) Skipped with a one-line reason without an adapter, unless
//! `RAYTRAIL_REQUIRE_GPU=1`.

mod common;

use raytrail_conformance::suite::{generated_scene, GENERATED_RAYS};
use raytrail_conformance::{ray_sets, NamedScene};
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::method::{Bvh2Method, Method, Query, StreamMethod, WideMethod};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Record, Trace, TraceOptions};
use raytrail_core::{Hit, Ray};
use raytrail_wgpu::{Dispatch, GpuConfig, TimingPlan, WgpuBackend, WgpuScene};
use std::sync::Arc;
use std::time::Duration;

fn open() -> Option<WgpuBackend> {
    common::open_or_skip("the wgpu stream and dispatch checks", WgpuBackend::new)
}

/// `named` prepared for every method, on `backend`, with the suite's ray sets (all of them in one).
fn scene_and_rays(backend: &WgpuBackend, named: &NamedScene) -> (WgpuScene, Vec<Ray>) {
    let bvh = SahBuilder::default().build(named.scene.triangles()).expect("SAH build");
    let prepared = Arc::new(PreparedScene::new(&named.scene, bvh, &Method::ALL).expect("prepare"));
    let scene = backend.prepare(prepared).expect("upload");
    let stack = TraceOptions::new(Bvh2Method::Stack);
    let mut trace = |rays: &[Ray]| {
        let mut hits = vec![Hit::MISS; rays.len()];
        backend.trace(&scene, rays, &stack, &mut hits).expect("trace");
        hits
    };
    let rays = ray_sets(&named.scene, GENERATED_RAYS, &mut trace).into_iter().flat_map(|s| s.rays).collect();
    (scene, rays)
}

fn trace(backend: &WgpuBackend, scene: &WgpuScene, rays: &[Ray], options: &TraceOptions) -> Vec<Hit> {
    let mut hits = vec![Hit::MISS; rays.len()];
    backend.trace(scene, rays, options, &mut hits).expect("trace");
    hits
}

#[test]
fn tracing_again_reuses_the_scenes_buffers() {
    let Some(backend) = open() else { return };
    let (scene, rays) = scene_and_rays(&backend, &generated_scene("sphereflake"));
    for method in [Method::Bvh2(Bvh2Method::Hash), Method::Wide(WideMethod::BVH8)] {
        let options = TraceOptions::new(method).record(Record::Counters);
        trace(&backend, &scene, &rays, &options);
        let after_first = scene.buffers_created();
        assert!(after_first > 0, "the first trace made the batch buffers");
        for _ in 0..3 {
            trace(&backend, &scene, &rays, &options);
            trace(&backend, &scene, &rays[..rays.len() / 3], &options.record(Record::Nothing));
        }
        assert_eq!(scene.buffers_created(), after_first, "{}: tracing again created buffers", method.name());
    }
    // A trace four times as long needs bigger buffers once, and then no more.
    let long: Vec<Ray> = rays.iter().cycle().take(rays.len() * 4).copied().collect();
    let options = TraceOptions::new(Bvh2Method::Stack);
    let before = scene.buffers_created();
    trace(&backend, &scene, &long, &options);
    let grown = scene.buffers_created();
    assert!(grown > before, "the longer trace grew the buffers");
    trace(&backend, &scene, &long, &options);
    assert_eq!(scene.buffers_created(), grown, "the second long trace reused them");
}

#[test]
fn streams_persistent_threads_and_workgroup_sizes_give_the_same_hits_and_counters() {
    let Some(backend) = open() else { return };
    // The adversarial rays at shared edges and vertices are the longest per ray.
    let (scene, rays) = scene_and_rays(&backend, &generated_scene("shared_edge_grid"));
    // Persistent threads in workgroups of 32 over small streamed batches run the whole suite in
    // conformance_persistent.rs; on lavapipe each workgroup size is every kernel compiled again
    // (0.3 to 4 seconds each), so this test adds one other size rather than repeating that one.
    let configs = [
        GpuConfig { batch_rays: 1000, in_flight: 2, ..GpuConfig::default() },
        GpuConfig { batch_rays: 777, in_flight: 3, dispatch: Dispatch::PERSISTENT, workgroup_size: 256 },
    ];
    let others: Vec<WgpuBackend> = configs.iter().map(|c| backend.configured(*c).expect("configured")).collect();
    let mut checked = 0;
    for method in Method::ALL.into_iter().filter(|m| !matches!(m, Method::Stream(_))) {
        for query in [Query::Closest, Query::Any] {
            let options = TraceOptions::new(method).query(query).record(Record::Counters);
            let mut want_hits = vec![Hit::MISS; rays.len()];
            let want = backend.trace(&scene, &rays, &options, &mut want_hits).expect("trace");
            for other in &others {
                let mut hits = vec![Hit::MISS; rays.len()];
                let got = other.trace(&scene, &rays, &options, &mut hits).expect("trace");
                let label = format!("{} {} {}", method.name(), query.name(), other.config().label());
                let differ = hits.iter().zip(&want_hits).filter(|(a, b)| !a.same_as(b)).count();
                assert_eq!(differ, 0, "{label}: {differ} of {} hits differ", rays.len());
                assert_eq!(got.counters, want.counters, "{label}: counters differ");
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 2 * (Method::ALL.len() - 1) * configs.len());
}

#[test]
fn settings_outside_the_adapters_limits_are_refused() {
    let Some(backend) = open() else { return };
    assert!(backend.configured(GpuConfig { workgroup_size: 1 << 16, ..GpuConfig::default() }).is_err());
    assert!(backend.configured(GpuConfig { in_flight: 0, ..GpuConfig::default() }).is_err());
}

#[test]
fn kernel_timing_and_transfer_figures() {
    let Some(backend) = open() else { return };
    let (scene, rays) = scene_and_rays(&backend, &generated_scene("sphereflake"));
    let options = TraceOptions::new(WideMethod::BVH4);
    let report = backend.trace(&scene, &rays, &options, &mut vec![Hit::MISS; rays.len()]).expect("trace");
    assert_eq!(report.transfer_bytes, rays.len() as u64 * 48, "rays up, hits down");
    assert!(report.seconds > 0.0);
    if !backend.has_gpu_timer() {
        assert!(backend.time_kernel(&scene, &rays, &options, &TimingPlan::default()).is_err());
        return;
    }
    assert!(report.kernel_seconds.is_some_and(|k| k > 0.0 && k <= report.seconds));
    let plan = TimingPlan { warm_up: Duration::from_millis(50), samples: 3, sample_length: Duration::from_millis(20) };
    for method in [Method::Wide(WideMethod::BVH4), Method::Stream(StreamMethod::Frustum8)] {
        for config in [GpuConfig::default(), GpuConfig { dispatch: Dispatch::PERSISTENT, ..GpuConfig::default() }] {
            let b = backend.configured(config).expect("configured");
            let t = b.time_kernel(&scene, &rays, &TraceOptions::new(method), &plan).expect("timing");
            assert_eq!(t.seconds.len(), 3);
            assert!(t.seconds.iter().all(|&s| s > 0.0), "{}: {:?}", method.name(), t.seconds);
            assert!(t.passes_per_sample >= 1 && t.warm_up_seconds >= 0.05);
            let (lo, hi) = t.spread();
            assert!(lo <= t.median_mrays_per_s() && t.median_mrays_per_s() <= hi);
        }
    }
    assert!(backend.time_kernel(&scene, &[], &options, &plan).is_err(), "no rays to time");
}
