//! What every conformance test file shares: the suite's scenes, ray sets, and how a mismatch is
//! reported (loudly, with the scene, the ray, both enumerations and where they part).
// Each test binary uses its own part of this module.
#![allow(dead_code, unused_macros)]

use raytrail_conformance::check::{check_ray_set, Context, Mismatch};
use raytrail_conformance::paths::{load_mesh_scene, scenes_dir};
use raytrail_conformance::rays::{ray_sets, RaySetSize};
use raytrail_conformance::NamedScene;
use raytrail_core::bvh2::Bvh2;
use raytrail_core::prepared::PreparedBvh2;
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::traverse::Method;
use raytrail_core::Hit;
use raytrail_cpu::CpuBackend;
use std::sync::Arc;

pub mod gpu;
#[macro_use]
mod suite;

/// Set to 1 to let the mesh tests pass without `../shared/scenes` (they then print why).
pub const ALLOW_MISSING: &str = "RAYTRAIL_ALLOW_MISSING_SCENES";

/// Loads a mesh of the suite; a missing scenes folder fails unless explicitly allowed.
pub fn mesh(file: &str) -> Option<NamedScene> {
    match load_mesh_scene(file) {
        Ok(s) => Some(s),
        Err(e) if std::env::var(ALLOW_MISSING).as_deref() == Ok("1") => {
            eprintln!("SKIPPED {file}: {e} ({ALLOW_MISSING}=1)");
            None
        }
        Err(e) => panic!(
            "{e}\n(scenes are read from {}; set RAYTRAIL_SCENES or run the fetch script)",
            scenes_dir().display()
        ),
    }
}

/// Runs every method on every ray set of `scene` with the tree `bvh` on the CPU backend and
/// panics with the first mismatches if any method parts from its reference.
pub fn check_scene(named: &NamedScene, bvh: Bvh2, size: RaySetSize) {
    let prepared = PreparedBvh2::new(&named.scene, bvh, &Method::ALL).expect("prepare");
    let backend = CpuBackend::new();
    let cpu = backend.prepare(Arc::new(prepared)).expect("prepare on the CPU");
    let mut trace_closest = |rays: &[raytrail_core::Ray]| {
        let mut hits = vec![Hit::MISS; rays.len()];
        backend.trace(&cpu, rays, &TraceOptions::new(Method::Stack), &mut hits).expect("trace");
        hits
    };
    let sets = ray_sets(&named.scene, size, &mut trace_closest);
    let mut mismatches: Vec<Mismatch> = Vec::new();
    let mut checked = 0;
    for set in &sets {
        let ctx = Context { scene: &named.name, ray_set: set.kind.name(), backend: "cpu" };
        mismatches.extend(check_ray_set(&backend, &cpu, ctx, &set.rays, &Method::ALL).expect("check"));
        checked += set.rays.len();
    }
    assert!(checked > 0, "{}: no rays were checked", named.name);
    if !mismatches.is_empty() {
        panic!("{}", mismatch_report(&named.name, "cpu", checked, &mismatches));
    }
    eprintln!("{}: {} rays x {} methods x 2 queries conform", named.name, checked, Method::ALL.len());
}

/// The loud failure message: how many mismatches, where, and the first ones in full.
pub fn mismatch_report(scene: &str, backend: &str, checked: usize, mismatches: &[Mismatch]) -> String {
    let mut msg = format!(
        "\n{} MISMATCHES in scene {scene} on {backend} ({checked} rays x {} methods x 2 queries checked). First ones:\n",
        mismatches.len(),
        Method::ALL.len()
    );
    for m in mismatches.iter().take(6) {
        msg.push_str(&m.to_string());
    }
    msg
}
