//! The loop guard (shaders/loop_guard.wgsl): a device that cuts a kernel's loops short must make
//! the trace fail with an error that says so, or trace the batch again one item per SIMD group,
//! and never return the misses of walks it stopped.
//!
//! The scenes are copies of one triangle, which no kd-tree split separates: one leaf holds them
//! all, and a ray through it tests every one in a single loop. Mesa's llvmpipe (lavapipe) counts
//! the loop iterations of a SIMD group of invocations against one limit of 65,535, over all the
//! items the group runs. On an adapter without such a limit every trace must succeed with the
//! serial backend's hits. Skipped with a one-line reason without an adapter, unless
//! `RAYTRAIL_REQUIRE_GPU=1`.

mod common;

use raytrail_conformance::reference::SerialBackend;
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::geometry::Triangle;
use raytrail_core::glam::Vec3;
use raytrail_core::method::{KdMethod, Method};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::scene::Scene;
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::{Hit, Ray};
use raytrail_wgpu::{Dispatch, GpuConfig, KernelForm, TimingPlan, WgpuBackend, WgpuScene};
use std::sync::Arc;
use std::time::Duration;

/// What the error of a cut trace says.
const CUT: &str = "cut the kernel's loops short";

/// `copies` copies of one triangle in the plane z = 0, prepared for `method` on `backend`, and
/// the serial backend's hits for `rays` rays straight down through it (each at t = 1).
fn stack_of_copies(
    backend: &WgpuBackend,
    copies: usize,
    method: Method,
    rays: usize,
) -> (WgpuScene, Vec<Ray>, Vec<Hit>) {
    let triangle = Triangle::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
    let scene = Scene::new(vec![triangle; copies]).expect("scene");
    let bvh = SahBuilder::default().build(scene.triangles()).expect("SAH build");
    let prepared = Arc::new(PreparedScene::new(&scene, bvh, &[method]).expect("prepare"));
    let rays = vec![Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, -1.0), 0.0, f32::INFINITY); rays];
    let serial = SerialBackend;
    let serial_scene = serial.prepare(prepared.clone()).expect("serial prepare");
    let mut expected = vec![Hit::MISS; rays.len()];
    serial.trace(&serial_scene, &rays, &TraceOptions::new(method), &mut expected).expect("serial trace");
    assert!(expected.iter().all(|h| h.t == 1.0), "every ray meets the triangle at t = 1");
    (backend.prepare(prepared).expect("upload"), rays, expected)
}

/// Whether `backend` runs on Mesa's llvmpipe, whose loop limit these tests reach.
fn limited(backend: &WgpuBackend) -> bool {
    backend.adapter().contains("llvmpipe")
}

/// Kernel timing of `rays`, which traces nothing again: on llvmpipe it must refuse walks it cut.
fn timing_refuses(backend: &WgpuBackend, scene: &WgpuScene, rays: &[Ray], options: &TraceOptions) -> bool {
    let plan = TimingPlan { warm_up: Duration::ZERO, samples: 1, sample_length: Duration::ZERO };
    backend.time_kernel(scene, rays, options, &plan).is_err_and(|e| e.to_string().contains(CUT))
}

#[test]
fn a_walk_the_device_cut_short_is_an_error_not_a_miss() {
    let grid = GpuConfig { dispatch: Dispatch::Grid, ..GpuConfig::default() };
    let persistent = GpuConfig { dispatch: Dispatch::Persistent { workgroups: 4 }, workgroup_size: 32, ..grid };
    // Both kernel forms: the guard must survive the SPIR-V path's compiler as well as WGSL's (an
    // adapter without SPIR-V passthrough skips, or fails under RAYTRAIL_REQUIRE_GPU=1, as the
    // persistent conformance suite does).
    for (form, config) in [(KernelForm::Wgsl, grid), (KernelForm::Wgsl, persistent), (KernelForm::Spirv, grid)] {
        let open = || WgpuBackend::with_kernel_form(form)?.configured(config);
        let Some(backend) = common::open_or_skip("the loop guard check", open) else {
            return;
        };
        // 70,000 triangle tests in one loop: more than llvmpipe allows a single ray, in any share.
        let options = TraceOptions::new(Method::Kd(KdMethod::Stack));
        let (scene, rays, expected) = stack_of_copies(&backend, 70_000, options.method, 8);
        let mut hits = vec![Hit::MISS; rays.len()];
        match backend.trace(&scene, &rays, &options, &mut hits) {
            Err(e) => {
                let message = e.to_string();
                assert!(message.contains(CUT), "{config:?}: another error: {message}");
                assert!(limited(&backend), "{config:?}: {} has no known loop limit, yet: {message}", backend.adapter());
                eprintln!("{config:?} on {}: refused, as it should be: {message}", backend.adapter());
                if backend.has_gpu_timer() {
                    assert!(timing_refuses(&backend, &scene, &rays, &options), "{config:?}: timed the cut walks");
                    eprintln!("{config:?}: kernel timing refused too");
                }
            }
            Ok(_) => {
                assert!(!limited(&backend), "{config:?}: llvmpipe cut the walk, and the trace returned {:?}", hits[0]);
                for (got, want) in hits.iter().zip(&expected) {
                    assert!(got.same_as(want), "{config:?}: {got:?}, serial {want:?}");
                }
            }
        }
    }
}

#[test]
fn a_batch_cut_short_is_traced_again_one_item_per_simd_group() {
    // One persistent workgroup of 32 for 64 packets: each invocation traces two, one after the
    // other. A packet tests its four rays lane by lane, so its loops add up to several times the
    // copies. On llvmpipe two packets in a row were cut at 6,000 copies (not at 4,000), and one
    // packet alone at 10,000 (not at 8,000): at 6,000 the first pass is cut, and a trace again
    // with one packet per SIMD group is not.
    let config =
        GpuConfig { dispatch: Dispatch::Persistent { workgroups: 1 }, workgroup_size: 32, ..GpuConfig::default() };
    let open = || WgpuBackend::with_kernel_form(KernelForm::Wgsl)?.configured(config);
    let Some(backend) = common::open_or_skip("the loop guard check", open) else {
        return;
    };
    let options = TraceOptions::new(Method::Kd(KdMethod::Packet));
    let (scene, rays, expected) = stack_of_copies(&backend, 6_000, options.method, 256);
    let mut hits = vec![Hit::MISS; rays.len()];
    backend.trace(&scene, &rays, &options, &mut hits).expect("the batch traced again one item per SIMD group");
    for (got, want) in hits.iter().zip(&expected) {
        assert!(got.same_as(want), "{got:?}, serial {want:?}");
    }
    // That the first pass was cut is shown by kernel timing, which does not trace again.
    if limited(&backend) && backend.has_gpu_timer() {
        assert!(
            timing_refuses(&backend, &scene, &rays, &options),
            "the first pass was not cut: the test misses its aim"
        );
        eprintln!(
            "on {}: the first pass was cut, and the trace again one item per SIMD group matched",
            backend.adapter()
        );
    }
}
