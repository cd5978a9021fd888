//! The conformance suite as a library: every scene × ray set × method × query check, for any
//! backend. A backend opts in from one of its test files with one line,
//! `raytrail_conformance::conformance_suite!(MyBackend::new());` (or `try MyBackend::new()` for a
//! constructor that can fail, such as a GPU's), which defines one test per [`Case`].
//!
//! Each case builds its trees, makes the ray sets, and checks on the backend every method against
//! its reference method ([`compare`](crate::check::compare)) and every outcome ray by ray against
//! the [`SerialBackend`] ([`compare_backends`](crate::check::compare_backends)). A method the
//! backend does not support fails the case: the suite never passes over a method in silence.

use crate::check::{check_against, check_complete, compare_hits, trace_all_recording, Context, Mismatch, PrimLeaves};
use crate::paths::{find_mesh, load_mesh_scene};
use crate::rays::{ray_sets, RaySetSize};
use crate::reference::SerialBackend;
use crate::scenes::{breathing, generated, tiny_cases, NamedScene};
use raytrail_core::bvh2::{Bvh2, SahBuilder, SbvhBuilder};
use raytrail_core::key::KeyWidth;
use raytrail_core::method::{Bvh2Method, Method, Query, WideMethod};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Record, Trace, TraceOptions};
use raytrail_core::wide::keyed::wide_key_width;
use raytrail_core::wide::WideBvh;
use raytrail_core::{Hit, Ray};
use std::any::Any;
use std::fmt::Display;
use std::sync::{Arc, Mutex, OnceLock};

/// Set to 1 to make a backend whose constructor fails (no GPU adapter) fail the suite instead of
/// skipping it (CI sets it, with a software Vulkan driver installed).
pub const REQUIRE_GPU: &str = "RAYTRAIL_REQUIRE_GPU";

/// Ray set sizes for the meshes.
pub const MESH_RAYS: RaySetSize = RaySetSize { width: 64, height: 48, uniform_count: 4096 };
/// Ray set sizes for the generated scenes.
pub const GENERATED_RAYS: RaySetSize = RaySetSize { width: 96, height: 72, uniform_count: 8192 };
/// Ray set sizes for the refit case (a quarter of [`GENERATED_RAYS`]: it traces its scene twice
/// over, and what it adds to the generated cases is the refit, not the rays).
pub const REFIT_RAYS: RaySetSize = RaySetSize { width: 48, height: 36, uniform_count: 2048 };
/// Ray set sizes for the tiny cases.
pub const TINY_RAYS: RaySetSize = RaySetSize { width: 16, height: 16, uniform_count: 512 };

/// The tree a case builds over its scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tree {
    /// Binned SAH ([`SahBuilder`]).
    Sah,
    /// PLOC, bottom-up clustering ([`raytrail_build::ploc`]).
    Ploc,
    /// Spatial splits ([`SbvhBuilder`]): a cut triangle is referenced from leaves on both sides of
    /// the plane, and every method must still find each hit once, in whichever leaf it meets it
    /// first.
    Sbvh,
}

/// One test of the suite. A scene with several trees is one case per tree, so that the tests are
/// short enough to spread evenly over the test threads (as one test, the sphereflake's three trees
/// ran last and alone on a software GPU for three minutes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Case {
    /// A grid of triangles sharing edges (SAH tree).
    SharedEdgeGrid,
    /// The sphereflake.
    Sphereflake(Tree),
    /// A random triangle soup.
    TriangleSoup(Tree),
    /// A stack of triangles deep enough to need 64-bit keys.
    DegenerateStack,
    /// A scene far from the origin.
    FarFromOrigin,
    /// The tiny hand-made cases.
    TinyCases,
    /// A mesh of the scenes folder (the file name).
    Mesh(&'static str, Tree),
    /// The sphereflake's tree refitted twice as its vertices move ([`breathing`]).
    Refit(Tree),
    /// Instances of three generated meshes against their flattened triangles
    /// ([`crate::instanced`]).
    Instanced,
    /// Every hit along each ray ([`Trace::all_hits`]) against a brute force and the exact
    /// reference, under every option ([`crate::all_hits::check_backend`]).
    AllHits,
    /// The nearest point on the mesh ([`Trace::nearest_points`]) against a brute force
    /// ([`crate::nearest::check_backend`]).
    Nearest,
}

/// Builds `tree` over `named`'s triangles.
pub fn build_tree(named: &NamedScene, tree: Tree) -> Bvh2 {
    let triangles = named.scene.triangles();
    match tree {
        Tree::Sah => SahBuilder::default().build(triangles).expect("SAH build"),
        Tree::Ploc => raytrail_build::ploc::build_ploc(triangles, 63).expect("PLOC build"),
        Tree::Sbvh => {
            let bvh = SbvhBuilder::default().build(triangles).expect("SBVH build");
            assert!(bvh.has_split_references(), "{}: the SBVH case should cut triangles", named.name);
            bvh
        }
    }
}

/// Runs one case on `backend`; panics with a loud report on any mismatch.
pub fn run_case<B: Trace>(backend: &B, case: Case) {
    let sah = |s: &NamedScene| build_tree(s, Tree::Sah);
    match case {
        Case::SharedEdgeGrid => check_scene(backend, &generated_scene("shared_edge_grid"), sah, GENERATED_RAYS),
        Case::Sphereflake(tree) => {
            check_scene(backend, &generated_scene("sphereflake"), |s| build_tree(s, tree), GENERATED_RAYS)
        }
        Case::TriangleSoup(tree) => {
            check_scene(backend, &generated_scene("triangle_soup"), |s| build_tree(s, tree), GENERATED_RAYS)
        }
        Case::DegenerateStack => {
            let s = generated_scene("degenerate_stack");
            let bvh = sah(&s);
            assert_eq!(bvh.stats().key_width, KeyWidth::W64, "depth {} should need 64-bit keys", bvh.stats().depth);
            let wide = WideBvh::<4>::build(&bvh, s.scene.triangles(), WideMethod::BVH4_HASH.collapse()).expect("bvh4");
            let depth = wide.stats().depth;
            assert_eq!(wide_key_width::<4>(depth), Some(KeyWidth::W64), "4-wide depth {depth} should need 64-bit keys");
            check_scene(backend, &s, |_| bvh.clone(), GENERATED_RAYS);
        }
        Case::FarFromOrigin => check_scene(backend, &generated_scene("far_from_origin"), sah, GENERATED_RAYS),
        Case::TinyCases => {
            for s in tiny_cases() {
                check_scene(backend, &s, sah, TINY_RAYS);
            }
        }
        Case::Mesh(file, tree) => {
            if let Some(s) = mesh(file) {
                check_scene(backend, &s, |s| build_tree(s, tree), MESH_RAYS);
            }
        }
        // A split tree refits to whole triangles' boxes: its clipped boxes do not survive.
        Case::Refit(tree) => check_refit(backend, &generated_scene("sphereflake"), |s| build_tree(s, tree), REFIT_RAYS),
        Case::Instanced => check_instanced(backend),
        Case::AllHits => crate::all_hits::check_backend(backend),
        Case::Nearest => crate::nearest::check_backend(backend),
    }
}

/// Runs one case on a backend `make` builds: one of those made by the binary's earlier tests if
/// one is idle, else a new one. A backend whose constructor fails is skipped with its reason
/// printed (from then on, for the whole binary), or fails when [`REQUIRE_GPU`] is 1.
///
/// A device and its compiled kernels are costly to make, so they are kept for the tests that
/// follow; but one backend per test running at once, not one for them all: a device runs one
/// dispatch at a time, and on a CPU adapter a dispatch of few workgroups keeps one core busy
/// (one device for two test threads left half of a two-core machine idle).
pub fn run_case_or_skip<B: Trace + 'static, E: Display>(make: impl FnOnce() -> Result<B, E>, case: Case) {
    static IDLE: Mutex<Vec<Box<dyn Any + Send + Sync>>> = Mutex::new(Vec::new());
    static UNAVAILABLE: OnceLock<String> = OnceLock::new();
    let idle = || IDLE.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let reason = UNAVAILABLE.get();
    let kept = if reason.is_none() { idle().pop() } else { None };
    let backend: Box<dyn Any + Send + Sync> = match (kept, reason) {
        (Some(b), _) => b,
        (None, Some(reason)) => return unavailable(reason, case),
        (None, None) => match make() {
            Ok(b) => Box::new(b),
            Err(e) => return unavailable(UNAVAILABLE.get_or_init(|| e.to_string()), case),
        },
    };
    match backend.downcast_ref::<B>() {
        Some(b) => run_case(b, case),
        None => panic!("one test binary opted into the suite with two backend types"),
    }
    // Kept only after the case passed: a backend that failed one is not trusted with the next.
    idle().push(backend);
}

/// A case whose backend could not be made: a failure when [`REQUIRE_GPU`] is 1, else a skip.
fn unavailable(reason: &str, case: Case) {
    if std::env::var(REQUIRE_GPU).as_deref() == Ok("1") {
        panic!("{REQUIRE_GPU}=1 but the backend is unavailable: {reason}")
    }
    static SAID: std::sync::Once = std::sync::Once::new();
    SAID.call_once(|| {
        eprintln!("SKIPPED the conformance suite: {reason} (set {REQUIRE_GPU}=1 to make this a failure)")
    });
    eprintln!("SKIPPED {case:?}");
}

/// A generated scene by name.
pub fn generated_scene(name: &str) -> NamedScene {
    generated().into_iter().find(|s| s.name == name).unwrap_or_else(|| panic!("no generated scene {name}"))
}

/// Loads a mesh of the suite; a missing one is skipped with a printed line ([`find_mesh`]), or
/// fails the case where [`REQUIRE_SCENES`](crate::paths::REQUIRE_SCENES) is 1. A mesh that is
/// there but does not load always fails.
pub fn mesh(file: &str) -> Option<NamedScene> {
    find_mesh(file)?;
    Some(load_mesh_scene(file).unwrap_or_else(|e| panic!("{e}")))
}

/// Runs every method for both queries on every ray set of `named`, with the tree `build` makes,
/// on `backend`, against each method's reference and against the serial backend; panics with the
/// first mismatches if there are any, or if the backend does not support a method.
pub fn check_scene<B: Trace>(
    backend: &B,
    named: &NamedScene,
    build: impl FnOnce(&NamedScene) -> Bvh2,
    size: RaySetSize,
) {
    assert_supports_all(backend);
    let prepared = Arc::new(PreparedScene::new(&named.scene, build(named), &Method::ALL).expect("prepare"));
    check_prepared(backend, named, prepared, size);
}

/// Fails loudly when `backend` does not support every method.
fn assert_supports_all<B: Trace>(backend: &B) {
    let unsupported: Vec<Method> = Method::ALL.into_iter().filter(|&m| !backend.supports(m)).collect();
    assert!(
        unsupported.is_empty(),
        "NOT CONFORMING: backend {} does not support {:?}; every backend must run every method",
        backend.name(),
        unsupported.iter().map(|m| m.name()).collect::<Vec<_>>()
    );
}

/// [`check_scene`] on a scene already prepared (`prepared` is `named`'s).
pub fn check_prepared<B: Trace>(backend: &B, named: &NamedScene, prepared: Arc<PreparedScene>, size: RaySetSize) {
    let serial = SerialBackend;
    let serial_scene = serial.prepare(prepared.clone()).expect("prepare on the serial backend");
    let scene = backend.prepare(prepared).expect("prepare on the backend");
    let mut trace_closest = |rays: &[Ray]| {
        let mut hits = vec![Hit::MISS; rays.len()];
        serial.trace(&serial_scene, rays, &TraceOptions::new(Bvh2Method::Stack), &mut hits).expect("trace");
        hits
    };
    let sets = ray_sets(&named.scene, size, &mut trace_closest);
    let mut mismatches: Vec<Mismatch> = Vec::new();
    let mut checked = 0;
    let leaves = PrimLeaves::new(&serial_scene.bvh);
    for set in &sets {
        let ctx = Context { scene: &named.name, ray_set: set.kind.name(), backend: backend.name() };
        mismatches.extend(
            check_against(&serial, &serial_scene, backend, &scene, ctx, &set.rays, &Method::ALL).expect("trace"),
        );
        let reference = trace_closest(&set.rays);
        for method in Method::STREAM {
            let opts = TraceOptions::new(method).record(Record::Enumerations);
            let mut hits = vec![Hit::MISS; set.rays.len()];
            let report = backend.trace(&scene, &set.rays, &opts, &mut hits).expect("trace");
            let enumerations = report.enumerations.unwrap_or_default();
            mismatches.extend(check_complete(ctx, &set.rays, method, &reference, &enumerations, &leaves));
        }
        checked += set.rays.len();
    }
    assert!(checked > 0, "{}: no rays were checked", named.name);
    if !mismatches.is_empty() {
        panic!("{}", mismatch_report(&named.name, backend.name(), checked, &mismatches));
    }
    eprintln!(
        "{}: {} rays x {} methods x 2 queries conform on {} and match the serial backend",
        named.name,
        checked,
        Method::ALL.len(),
        backend.name()
    );
}

/// The refit case: `named`'s tree built where its triangles are, then refitted to where they
/// moved ([`PreparedScene::refit`]; [`breathing`] at two times, the second refit from the first).
/// After each refit, every method's hits bit for bit against a scene prepared afresh from the
/// moved triangles with a tree of their own ([`refit_mismatches`]); after the second, the whole
/// check of any prepared scene ([`check_prepared`]: every method against its reference and the
/// serial backend, node visits included).
pub fn check_refit<B: Trace>(backend: &B, named: &NamedScene, build: impl Fn(&NamedScene) -> Bvh2, size: RaySetSize) {
    assert_supports_all(backend);
    let mut prepared = PreparedScene::new(&named.scene, build(named), &Method::ALL).expect("prepare");
    const PHASES: [f32; 2] = [1.3, 2.9];
    for phase in PHASES {
        let moved = breathing(&named.scene, phase).expect("moved scene");
        let moved = NamedScene::new(format!("{} breathing at {phase}", named.name), moved);
        prepared.refit(&moved.scene).expect("refit");
        let refitted = Arc::new(prepared.clone());
        if phase == PHASES[PHASES.len() - 1] {
            check_prepared(backend, &moved, refitted.clone(), size);
        }
        let fresh = Arc::new(PreparedScene::new(&moved.scene, build(&moved), &Method::ALL).expect("prepare"));
        let mismatches = refit_mismatches(backend, refitted, fresh, &moved, size);
        if !mismatches.is_empty() {
            panic!("REFIT: {}", mismatch_report(&moved.name, backend.name(), 0, &mismatches));
        }
        eprintln!("{}: every method's hits on the refitted tree are a fresh tree's on {}", moved.name, backend.name());
    }
}

/// Every method's hits on `refitted` (a scene refitted to `named`'s triangles) traced on
/// `backend`, against the stack method's on `fresh` (the same triangles prepared afresh) on the
/// serial backend, for both queries on every ray set: the mismatches. Hits do not depend on the
/// tree (every method finds the same ones on any tree), so any difference is a box the refit left
/// stale or a triangle it left where it was.
pub fn refit_mismatches<B: Trace>(
    backend: &B,
    refitted: Arc<PreparedScene>,
    fresh: Arc<PreparedScene>,
    named: &NamedScene,
    size: RaySetSize,
) -> Vec<Mismatch> {
    let serial = SerialBackend;
    let fresh = serial.prepare(fresh).expect("prepare on the serial backend");
    let scene = backend.prepare(refitted).expect("prepare on the backend");
    let stack = [Method::Bvh2(Bvh2Method::Stack)];
    let mut trace_closest = |rays: &[Ray]| {
        let mut hits = vec![Hit::MISS; rays.len()];
        serial.trace(&fresh, rays, &TraceOptions::new(stack[0]), &mut hits).expect("trace");
        hits
    };
    let versus = format!("{} refitted vs fresh", backend.name());
    let mut mismatches = Vec::new();
    for set in ray_sets(&named.scene, size, &mut trace_closest) {
        let ctx = Context { scene: &named.name, ray_set: set.kind.name(), backend: backend.name() };
        for query in Query::ALL {
            // Hits alone are compared here, so no node visits are recorded (`check_prepared` checks
            // those on the refitted tree).
            let expected =
                trace_all_recording(&serial, &fresh, &set.rays, &stack, query, Record::Nothing).expect("trace");
            let got =
                trace_all_recording(backend, &scene, &set.rays, &Method::ALL, query, Record::Nothing).expect("trace");
            // Each method against the fresh scene's stack method: the same outcome under each name.
            let expected: Vec<_> =
                got.iter().map(|o| crate::check::Outcome { method: o.method, ..expected[0].clone() }).collect();
            mismatches.extend(compare_hits(ctx, &versus, &set.rays, &expected, &got));
        }
    }
    mismatches
}

/// The instanced case: [`instanced_mismatches`](crate::instanced::instanced_mismatches) on
/// [`instanced_case`](crate::instanced::instanced_case); panics with the first disagreements.
pub fn check_instanced<B: Trace>(backend: &B) {
    let case = crate::instanced::instanced_case();
    let wrong = crate::instanced::instanced_mismatches(backend, &case, &case.instances);
    if !wrong.is_empty() {
        let first: Vec<&str> = wrong.iter().take(6).map(String::as_str).collect();
        panic!("\n{} INSTANCED MISMATCHES on {}. First ones:\n{}", wrong.len(), backend.name(), first.join("\n"));
    }
    eprintln!(
        "instanced: {} methods x 2 queries and every mask agree with the flattened triangles on {}",
        crate::instanced::INSTANCED_METHODS.len(),
        backend.name()
    );
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

/// Defines one `#[test]` per [`Case`] of the suite for a backend:
/// `conformance_suite!(CpuBackend::new());`, or with `try` for a constructor returning a
/// `Result` (a backend is then made once for each test running at once and kept for the tests
/// after it, and skipped if it cannot be made unless [`REQUIRE_GPU`] is 1: [`run_case_or_skip`]).
/// `small: try ...` defines only the cases that reach every kernel, both key widths and each
/// tree builder once without the large meshes (the generated scenes, the sphereflake with SAH and
/// SBVH trees, the soup with a PLOC tree, the Cornell box and the teapot), for a second
/// configuration of a backend whose every kernel the full suite already ran on every scene and
/// tree.
#[macro_export]
macro_rules! conformance_suite {
    (small: try $make:expr) => {
        $crate::conformance_suite!(@small |case| $crate::suite::run_case_or_skip(|| $make, case));
    };
    (try $make:expr) => {
        $crate::conformance_suite!(@cases |case| $crate::suite::run_case_or_skip(|| $make, case));
    };
    ($make:expr) => {
        $crate::conformance_suite!(@cases |case| $crate::suite::run_case(&$make, case));
    };
    (@small $run:expr) => {
        $crate::conformance_suite!(@each $run;
            shared_edge_grid => SharedEdgeGrid,
            sphereflake => Sphereflake(Sah),
            sphereflake_with_sbvh => Sphereflake(Sbvh),
            triangle_soup_with_ploc => TriangleSoup(Ploc),
            degenerate_stack_needs_and_uses_64_bit_keys => DegenerateStack,
            far_from_origin => FarFromOrigin,
            tiny_cases => TinyCases,
            instanced => Instanced,
            all_hits => AllHits,
            nearest => Nearest,
            cornell_box => Mesh("cornell_box.obj", Sah),
            teapot => Mesh("teapot.obj", Sah),
        );
    };
    (@cases $run:expr) => {
        $crate::conformance_suite!(@small $run);
        $crate::conformance_suite!(@each $run;
            sphereflake_with_ploc => Sphereflake(Ploc),
            triangle_soup => TriangleSoup(Sah),
            triangle_soup_with_sbvh => TriangleSoup(Sbvh),
            kitchen => Mesh("kitchen.obj", Sah),
            sponza => Mesh("sponza.obj", Sah),
            bunny => Mesh("bunny.obj", Sah),
            dragon_res2 => Mesh("dragon_vrip_res2.ply.gz", Sah),
            dragon_full => Mesh("dragon_vrip.ply.gz", Sah),
            bunny_with_ploc => Mesh("bunny.obj", Ploc),
            cornell_box_with_sbvh => Mesh("cornell_box.obj", Sbvh),
            sponza_with_sbvh => Mesh("sponza.obj", Sbvh),
            refit_sphereflake => Refit(Sah),
            refit_sphereflake_with_sbvh => Refit(Sbvh),
        );
    };
    (@each $run:expr; $($name:ident => $case:expr,)*) => {
        $(
            #[test]
            fn $name() {
                #[allow(unused_imports)]
                use $crate::suite::{Case::*, Tree::*};
                let run: fn($crate::suite::Case) = $run;
                run($case);
            }
        )*
    };
}
