//! The loop guard (shaders/loop_guard.wgsl): a device that cuts a kernel's loops short must make
//! the trace fail with an error that says so, never return the misses of walks it stopped.
//!
//! The scene is 70,000 copies of one triangle, which no kd-tree split separates: one leaf holds
//! them all, and a ray through it tests every one in a single loop. Mesa's llvmpipe (lavapipe)
//! ends that loop at 65,535 iterations, so on it the trace must fail; on an adapter without such a
//! limit the trace must succeed with the serial backend's hits. Kernel timing refuses the same way. Skipped with a one-line reason
//! without an adapter, unless `RAYTRAIL_REQUIRE_GPU=1`.

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
use raytrail_wgpu::{Dispatch, GpuConfig, KernelForm, TimingPlan, WgpuBackend};
use std::sync::Arc;
use std::time::Duration;

/// More triangles in one leaf than llvmpipe lets a group of invocations loop over.
const COPIES: usize = 70_000;

#[test]
fn a_walk_the_device_cut_short_is_an_error_not_a_miss() {
    let grid = GpuConfig { dispatch: Dispatch::Grid, ..GpuConfig::default() };
    let persistent = GpuConfig { dispatch: Dispatch::Persistent { workgroups: 4 }, workgroup_size: 32, ..grid };
    // Both kernel forms: the guard must survive the SPIR-V path's compiler as well as WGSL's.
    for (form, config) in [(KernelForm::Auto, grid), (KernelForm::Auto, persistent), (KernelForm::Spirv, grid)] {
        let open = || WgpuBackend::with_kernel_form(form)?.configured(config);
        let Some(backend) = common::open_or_skip("the loop guard check", open) else {
            return;
        };
        let triangle = Triangle::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
        let scene = Scene::new(vec![triangle; COPIES]).expect("scene");
        let method = Method::Kd(KdMethod::Stack);
        let bvh = SahBuilder::default().build(scene.triangles()).expect("SAH build");
        let prepared = Arc::new(PreparedScene::new(&scene, bvh, &[method]).expect("prepare"));
        let rays = vec![Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, -1.0), 0.0, f32::INFINITY); 8];
        let options = TraceOptions::new(method);

        let serial = SerialBackend;
        let serial_scene = serial.prepare(prepared.clone()).expect("serial prepare");
        let mut expected = vec![Hit::MISS; rays.len()];
        serial.trace(&serial_scene, &rays, &options, &mut expected).expect("serial trace");
        assert!(expected.iter().all(|h| h.t == 1.0), "every ray meets the triangle at t = 1");

        let device_scene = backend.prepare(prepared).expect("upload");
        let mut hits = vec![Hit::MISS; rays.len()];
        let outcome = backend.trace(&device_scene, &rays, &options, &mut hits);
        let limited = backend.adapter().contains("llvmpipe");
        match outcome {
            Err(e) => {
                let message = e.to_string();
                assert!(message.contains("cut the kernel's loops short"), "{config:?}: another error: {message}");
                assert!(limited, "{config:?}: {} has no known loop limit, yet: {message}", backend.adapter());
                eprintln!("{config:?} on {}: refused, as it should be: {message}", backend.adapter());
                // Nor is a time reported for the walks it cut.
                if backend.has_gpu_timer() {
                    let plan = TimingPlan { warm_up: Duration::ZERO, samples: 1, sample_length: Duration::ZERO };
                    let timed = backend.time_kernel(&device_scene, &rays, &options, &plan);
                    let refused = timed.as_ref().is_err_and(|e| e.to_string().contains("cut the kernel's loops short"));
                    assert!(refused, "{config:?}: timing the cut walks gave {:?}", timed.map(|t| t.seconds));
                    eprintln!("{config:?}: kernel timing refused too");
                }
            }
            Ok(_) => {
                assert!(!limited, "{config:?}: llvmpipe cut the walk, and the trace returned {:?}", hits[0]);
                for (got, want) in hits.iter().zip(&expected) {
                    assert!(got.same_as(want), "{config:?}: {got:?}, serial {want:?}");
                }
            }
        }
    }
}
