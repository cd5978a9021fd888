//! The wgpu half of the suite: one device for the whole test binary, and the check that the GPU
//! agrees with itself across methods and with the CPU ray by ray.

use super::mismatch_report;
use raytrail_conformance::check::{check_against, Context, Mismatch};
use raytrail_conformance::rays::{ray_sets, RaySetSize};
use raytrail_conformance::NamedScene;
use raytrail_core::bvh2::Bvh2;
use raytrail_core::prepared::PreparedBvh2;
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::traverse::Method;
use raytrail_core::Hit;
use raytrail_cpu::CpuBackend;
use raytrail_wgpu::{WgpuBackend, REQUIRE_GPU};
use std::io::Write;
use std::sync::{Arc, OnceLock};

/// The device, opened once; `Err` holds why there is none.
fn backend() -> &'static Result<WgpuBackend, String> {
    static GPU: OnceLock<Result<WgpuBackend, String>> = OnceLock::new();
    GPU.get_or_init(|| {
        let b = WgpuBackend::new().map_err(|e| e.to_string());
        if let Ok(b) = &b {
            eprintln!("wgpu conformance on {}", b.adapter());
        }
        b
    })
}

/// The GPU backend, or `None` after printing a one-line reason; a missing adapter fails the test
/// instead when `RAYTRAIL_REQUIRE_GPU=1` (as in CI).
pub fn gpu_or_skip(what: &str) -> Option<&'static WgpuBackend> {
    match backend() {
        Ok(b) => Some(b),
        Err(e) if std::env::var(REQUIRE_GPU).as_deref() == Ok("1") => {
            panic!("{REQUIRE_GPU}=1 but the wgpu backend is unavailable: {e}")
        }
        Err(e) => {
            // Once per test binary, past the harness's output capture, so a plain `cargo test`
            // shows why the GPU part did not run.
            static SAID: std::sync::Once = std::sync::Once::new();
            SAID.call_once(|| {
                let _ = writeln!(
                    std::io::stderr(),
                    "SKIPPED the wgpu conformance suite: {e} (set {REQUIRE_GPU}=1 to make this a failure)"
                );
            });
            eprintln!("SKIPPED wgpu {what}");
            None
        }
    }
}

/// Runs every method for both queries on every ray set of `scene` on the GPU and the CPU;
/// panics with the first mismatches if the GPU parts from the CPU or a method from its reference.
pub fn check_scene_gpu(named: &NamedScene, bvh: Bvh2, size: RaySetSize) {
    let Some(gpu) = gpu_or_skip(&format!("conformance on {}", named.name)) else {
        return;
    };
    let prepared = Arc::new(PreparedBvh2::new(&named.scene, bvh, &Method::ALL).expect("prepare"));
    let cpu = CpuBackend::new();
    let cpu_scene = cpu.prepare(prepared.clone()).expect("prepare on the CPU");
    let gpu_scene = gpu.prepare(prepared).expect("upload to the GPU");
    let mut trace_closest = |rays: &[raytrail_core::Ray]| {
        let mut hits = vec![Hit::MISS; rays.len()];
        cpu.trace(&cpu_scene, rays, &TraceOptions::new(Method::Stack), &mut hits).expect("trace");
        hits
    };
    let sets = ray_sets(&named.scene, size, &mut trace_closest);
    let mut mismatches: Vec<Mismatch> = Vec::new();
    let mut checked = 0;
    for set in &sets {
        let ctx = Context { scene: &named.name, ray_set: set.kind.name(), backend: "wgpu" };
        mismatches
            .extend(check_against(&cpu, &cpu_scene, gpu, &gpu_scene, ctx, &set.rays, &Method::ALL).expect("trace"));
        checked += set.rays.len();
    }
    assert!(checked > 0, "{}: no rays were checked", named.name);
    if !mismatches.is_empty() {
        panic!("{}", mismatch_report(&named.name, "wgpu", checked, &mismatches));
    }
    eprintln!(
        "{}: {} rays x {} methods x 2 queries conform on wgpu and match the CPU",
        named.name,
        checked,
        Method::ALL.len()
    );
}
