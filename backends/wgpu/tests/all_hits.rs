//! Long hit lists on the device: rays through a stack of triangles find more hits than a ray's
//! first slot holds (shaders/all_hits.wgsl), so the backend traces them again with larger slots;
//! the lists must still be the core's bit for bit under every option. The suite's all-hits case
//! (conformance.rs) covers the ordinary scenes.
//!
//! Without an adapter the test prints a one-line SKIPPED reason and passes, unless
//! `RAYTRAIL_REQUIRE_GPU=1`.

mod common;

use raytrail_conformance::all_hits::{prepared_for_queries, OPTIONS};
use raytrail_conformance::rays::{ray_sets, RaySetSize};
use raytrail_conformance::scenes::{degenerate_stack, DEGENERATE_STACK_LAYERS, SCENE_SEED};
use raytrail_conformance::SerialBackend;
use raytrail_core::all_hits::{AllHits, AllHitsOptions};
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::method::Bvh2Method;
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::{Hit, Ray};
use raytrail_wgpu::WgpuBackend;

#[test]
fn lists_longer_than_a_first_slot_are_the_cores_bit_for_bit() {
    let Some(gpu) = common::open_or_skip("the long all-hits lists test", WgpuBackend::new) else { return };
    let scene = degenerate_stack(DEGENERATE_STACK_LAYERS, SCENE_SEED);
    let bvh = SahBuilder::default().build(scene.triangles()).expect("SAH build");
    let prepared = prepared_for_queries(&scene, bvh);
    let mut closest = |rays: &[Ray]| {
        let mut hits = vec![Hit::MISS; rays.len()];
        SerialBackend.trace(&prepared, rays, &TraceOptions::new(Bvh2Method::Stack), &mut hits).expect("trace");
        hits
    };
    let size = RaySetSize { width: 24, height: 18, uniform_count: 256 };
    let rays: Vec<Ray> = ray_sets(&scene, size, &mut closest).into_iter().flat_map(|s| s.rays).collect();
    let device = gpu.prepare(prepared.clone()).expect("upload");
    let limited = AllHitsOptions { max_hits: 20, merge_equal_t: false };
    for options in OPTIONS.iter().chain([&limited]) {
        let want = AllHits::trace(&prepared, &rays, options).expect("the core's lists");
        let got = gpu.all_hits(&device, &rays, options).expect("the device's lists");
        for (i, ray) in rays.iter().enumerate() {
            let bits =
                |l: &[Hit]| l.iter().map(|h| (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits())).collect::<Vec<_>>();
            assert_eq!(bits(got.ray(i).unwrap()), bits(want.ray(i).unwrap()), "{options:?}, ray {i}: {ray:?}");
            assert_eq!(got.is_truncated(i), want.is_truncated(i), "{options:?}, ray {i}");
        }
        // Lists past the first slot's eight hits, so the larger slots were used.
        if !options.merge_equal_t && options.max_hits > 8 {
            let longest = got.iter().map(<[Hit]>::len).max().unwrap_or(0);
            assert!(longest > 8, "{options:?}: the longest list holds {longest} hits");
        }
    }
}
