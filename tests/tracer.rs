//! The high-level API: [`Tracer`] answers as the expert path does, counts or rejects untraceable
//! rays, and the expert path rejects a tree built for other triangles.

use raytrail::core::method::{Bvh2Method, WideMethod};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::scene::Scene;
use raytrail::core::trace::{Trace, TraceOptions};
use raytrail::cpu::CpuBackend;
use raytrail::{Builder, Error, Hit, Method, Query, Ray, Tracer, Vec3, AUTO_MIN_RAYS, AUTO_WALKS};
use raytrail_conformance::rays::{default_light, primary, scene_epsilon, shadow};
use raytrail_conformance::suite::generated_scene;
use std::sync::Arc;

/// The sphereflake as arrays, as a user would hold it: vertices and index triples.
fn arrays(scene: &Scene) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let vertices: Vec<[f32; 3]> = scene.triangles().iter().flat_map(|t| t.v.map(|v| v.to_array())).collect();
    let triangles = (0..scene.triangles().len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    (vertices, triangles)
}

/// The stack method's answers, through the expert path.
fn stack_hits(scene: &Scene, rays: &[Ray], query: Query) -> Vec<Hit> {
    let method = Method::Bvh2(Bvh2Method::Stack);
    let prepared = PreparedScene::new(scene, Builder::Sah.build(scene).unwrap(), &[method]).unwrap();
    let backend = CpuBackend::new();
    let cpu = backend.prepare(Arc::new(prepared)).unwrap();
    let mut hits = vec![Hit::MISS; rays.len()];
    backend.trace(&cpu, rays, &TraceOptions::new(method).query(query), &mut hits).unwrap();
    hits
}

#[test]
fn a_tracer_from_arrays_answers_as_the_stack_method_in_every_form() {
    let scene = generated_scene("sphereflake").scene;
    let (vertices, triangles) = arrays(&scene);
    let tracer = Tracer::new(&vertices, &triangles).unwrap();
    assert_eq!(tracer.triangle_count(), scene.triangles().len());
    // Large enough that the tracer times its walks on a sample.
    let camera = primary(&scene, 320, 240);
    assert!(camera.len() >= AUTO_MIN_RAYS);
    let want = stack_hits(&scene, &camera, Query::Closest);
    let got = tracer.intersect(&camera).unwrap();
    assert!(got.iter().zip(&want).all(|(a, b)| a.same_as(b)), "batch hits differ from the stack method's");
    assert!(got.iter().any(Hit::is_hit) && got.iter().any(|h| !h.is_hit()));
    assert!(AUTO_WALKS.contains(&tracer.method_for(&camera, Query::Closest).unwrap()));
    // Slice in, slice out.
    let mut into = vec![Hit::MISS; camera.len()];
    let report = tracer.intersect_into(&camera, &mut into).unwrap();
    assert_eq!((report.rays, report.untraceable, report.refused), (camera.len(), 0, 0));
    assert!(into.iter().zip(&want).all(|(a, b)| a.same_as(b)));
    // One ray at a time, hits and misses.
    for (ray, want) in camera.iter().zip(&want).step_by(997) {
        let one = tracer.intersect_one(ray).unwrap();
        assert_eq!(one.map(|h| (h.prim, h.t.to_bits())), want.is_hit().then_some((want.prim, want.t.to_bits())));
    }
    // Occlusion: shadow rays toward a light, against the stack method's any-hit answers.
    let b = scene.bounds();
    let shadows = shadow(&camera, &want, default_light(b), scene_epsilon(b));
    let want_any = stack_hits(&scene, &shadows, Query::Any);
    let blocked = tracer.occluded(&shadows).unwrap();
    assert!(blocked.iter().zip(&want_any).all(|(&o, h)| o == h.is_hit()), "occlusion differs");
    assert!(blocked.iter().any(|&o| o) && blocked.iter().any(|&o| !o));
    let mut again = vec![true; shadows.len()];
    tracer.occluded_into(&shadows, &mut again).unwrap();
    assert_eq!(again, blocked);
    for (ray, &o) in shadows.iter().zip(&blocked).step_by(101) {
        assert_eq!(tracer.occluded_one(ray).unwrap(), o);
    }
}

#[test]
fn a_named_method_and_thread_count_are_used_for_every_batch() {
    let scene = generated_scene("sphereflake").scene;
    let rays = primary(&scene, 64, 48);
    let method = Method::Wide(WideMethod::BVH4_HASH);
    let tracer = Tracer::builder().method(method).threads(1).tree_builder(Builder::Sah).build_scene(&scene).unwrap();
    assert_eq!(tracer.method_for(&rays, Query::Closest).unwrap(), method);
    // Only that method's tables were built.
    assert!(tracer.prepared().check_prepared(method).is_ok());
    assert!(tracer.prepared().check_prepared(Method::Wide(WideMethod::BVH8)).is_err());
    let want = stack_hits(&scene, &rays, Query::Closest);
    assert!(tracer.intersect(&rays).unwrap().iter().zip(&want).all(|(a, b)| a.same_as(b)));
}

#[test]
fn untraceable_rays_are_counted_or_rejected() {
    let tri = Tracer::new(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]]).unwrap();
    let good = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z, 0.0, f32::INFINITY);
    let bad = [
        Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::ZERO, 0.0, f32::INFINITY),
        Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::new(f32::NAN, 0.0, -1.0), 0.0, f32::INFINITY),
        Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z, 2.0, 1.0),
    ];
    let rays = [good, bad[0], good, bad[1], bad[2]];
    let mut hits = [Hit::MISS; 5];
    let report = tri.intersect_into(&rays, &mut hits).unwrap();
    assert_eq!(report.untraceable, 3);
    assert_eq!(hits.map(|h| h.is_hit()), [true, false, true, false, false]);
    for b in &bad {
        assert_eq!(tri.intersect_one(b).unwrap(), None);
        assert!(!tri.occluded_one(b).unwrap());
    }
    let strict = Tracer::builder()
        .reject_untraceable(true)
        .build(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]])
        .unwrap();
    match strict.intersect(&rays) {
        Err(Error::UntraceableRays { count: 3, first: 1 }) => {}
        other => panic!("expected UntraceableRays {{ count: 3, first: 1 }}, got {other:?}"),
    }
    assert!(matches!(strict.occluded_one(&bad[2]), Err(Error::UntraceableRays { count: 1, first: 0 })));
    assert!(strict.intersect_one(&good).unwrap().is_some());
}

#[test]
fn bad_input_is_a_typed_error() {
    let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let index_past_the_vertices = Tracer::new(&v, &[[0, 1, 3]]).unwrap_err();
    assert!(matches!(
        index_past_the_vertices,
        Error::Core(raytrail::core::Error::VertexIndexOutOfRange { triangle: 0, index: 3, vertex_count: 3 })
    ));
    assert!(matches!(Tracer::new(&v, &[]), Err(Error::Core(raytrail::core::Error::EmptyScene))));
    let nan = [[0.0, 0.0, 0.0], [1.0, f32::NAN, 0.0], [0.0, 1.0, 0.0]];
    assert!(matches!(
        Tracer::new(&nan, &[[0, 1, 2]]),
        Err(Error::Core(raytrail::core::Error::NonFiniteVertex { vertex: 1 }))
    ));
    let tracer = Tracer::new(&v, &[[0, 1, 2]]).unwrap();
    let rays = [Ray::new(Vec3::ONE, -Vec3::Z, 0.0, 1.0); 2];
    let mismatch = tracer.intersect_into(&rays, &mut [Hit::MISS; 3]).unwrap_err();
    assert!(matches!(mismatch, Error::Core(raytrail::core::Error::BufferMismatch { rays: 2, hits: 3 })));
    assert!(matches!(
        tracer.occluded_into(&rays, &mut [false; 1]),
        Err(Error::Core(raytrail::core::Error::BufferMismatch { .. }))
    ));
    // Errors are std errors with a cause and a one-line message naming the problem.
    let e: &dyn std::error::Error = &index_past_the_vertices;
    assert!(e.source().is_some());
    assert!(e.to_string().contains("vertex 3"), "{e}");
}

#[test]
fn a_tree_built_for_other_triangles_is_rejected() {
    let scene = generated_scene("sphereflake").scene;
    let bvh = Builder::Sah.build(&scene).unwrap();
    // The same triangle count, one triangle moved by 10 units.
    let mut moved = scene.triangles().to_vec();
    for v in &mut moved[17].v {
        *v += Vec3::splat(10.0);
    }
    let moved = Scene::new(moved).unwrap();
    for method in [Method::Bvh2(Bvh2Method::Stack), Method::Wide(WideMethod::BVH8)] {
        match PreparedScene::new(&moved, bvh.clone(), &[method]) {
            Err(raytrail::core::Error::TreeMismatch { .. }) => {}
            other => panic!("{method}: expected TreeMismatch, got {:?}", other.map(|_| "a prepared scene")),
        }
    }
    // Fewer triangles: also a mismatch, not a panic.
    let fewer = Scene::new(scene.triangles()[..100].to_vec()).unwrap();
    assert!(matches!(
        PreparedScene::new(&fewer, bvh.clone(), &[Method::Bvh2(Bvh2Method::Stack)]),
        Err(raytrail::core::Error::TreeMismatch { .. })
    ));
    // Its own tree passes.
    assert!(PreparedScene::new(&scene, bvh, &[Method::Bvh2(Bvh2Method::Stack)]).is_ok());
}

#[test]
fn the_chunk_check_frames_as_needs_framing_and_counts_as_is_traceable() {
    let scene = generated_scene("sphereflake").scene;
    let prepared =
        PreparedScene::new(&scene, Builder::Sah.build(&scene).unwrap(), &[Method::Bvh2(Bvh2Method::Stack)]).unwrap();
    let mut rays = raytrail_conformance::rays::adversarial(&scene, 7);
    rays.extend(primary(&scene, 16, 16));
    let untraceable = rays.iter().filter(|r| !r.is_traceable()).count();
    assert!(untraceable > 0, "the adversarial set holds untraceable rays");
    let (mut framed, mut counted) = (0, 0);
    for chunk in rays.chunks(37) {
        let check = prepared.check_rays(chunk);
        assert_eq!(check.needs_framing, prepared.needs_framing(chunk));
        framed += usize::from(check.needs_framing);
        counted += check.untraceable;
    }
    assert_eq!(counted, untraceable);
    assert!(framed > 0, "some adversarial chunks need framing");
    // And the CPU backend's report counts them, framed or not.
    let backend = CpuBackend::new();
    let cpu = backend.prepare(Arc::new(prepared)).unwrap();
    let mut hits = vec![Hit::MISS; rays.len()];
    let report = backend.trace(&cpu, &rays, &TraceOptions::new(Bvh2Method::Stack), &mut hits).unwrap();
    assert_eq!(report.untraceable, untraceable);
}

#[test]
fn a_refitted_tracer_answers_as_one_built_from_the_moved_vertices() {
    let scene = generated_scene("sphereflake").scene;
    let (vertices, triangles) = arrays(&scene);
    let mut tracer = Tracer::new(&vertices, &triangles).unwrap();
    let held = tracer.prepared().clone();
    for phase in [0.8f32, 2.5] {
        let moved = raytrail_conformance::scenes::breathing(&scene, phase).unwrap();
        let (moved_vertices, _) = arrays(&moved);
        tracer.refit(&moved_vertices, &triangles).unwrap();
        let camera = primary(&moved, 320, 240);
        let want = stack_hits(&moved, &camera, Query::Closest);
        let got = tracer.intersect(&camera).unwrap();
        assert!(got.iter().zip(&want).all(|(a, b)| a.same_as(b)), "phase {phase}: hits differ from a fresh tree's");
        let b = moved.bounds();
        let shadows = shadow(&camera, &want, default_light(b), scene_epsilon(b));
        let want_any = stack_hits(&moved, &shadows, Query::Any);
        let blocked = tracer.occluded(&shadows).unwrap();
        assert!(blocked.iter().zip(&want_any).all(|(&o, h)| o == h.is_hit()), "phase {phase}: occlusion differs");
    }
    // The prepared scene held before the refits is the unmoved one still.
    held.bvh.check_bounds(scene.triangles()).unwrap();
    // A refit to another triangle count is an error that leaves the tracer as it was.
    let before = tracer.intersect(&primary(&scene, 64, 48)).unwrap();
    let err = tracer.refit(&vertices, &triangles[1..]).unwrap_err();
    assert!(matches!(err, Error::Core(raytrail::core::Error::TreeMismatch { .. })), "{err:?}");
    assert!(tracer.intersect(&primary(&scene, 64, 48)).unwrap().iter().zip(&before).all(|(a, b)| a.same_as(b)));
}

/// A large batch in no order, which `auto` may sort (and walk in packets), answers as the stack
/// method does, hit for hit in the caller's order; a camera's batch is never sorted.
#[test]
fn auto_on_a_large_shuffled_batch_answers_in_the_given_order() {
    use raytrail::core::trace_order::{TraceOrder, SORT_MIN_RAYS};
    let scene = generated_scene("sphereflake").scene;
    let (vertices, triangles) = arrays(&scene);
    let tracer = Tracer::new(&vertices, &triangles).unwrap();
    let (lo, hi) = (scene.bounds().min, scene.bounds().max);
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let rays: Vec<Ray> = (0..SORT_MIN_RAYS + 1000)
        .map(|_| {
            let o = lo + (hi - lo) * Vec3::new(next(), next(), next());
            Ray::new(o, Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5), 0.0, f32::INFINITY)
        })
        .collect();
    assert_eq!(TraceOrder::for_batch(&rays), TraceOrder::Sorted);
    // Whether it sorts also depends on how slow the rays are on this machine (a timed sample):
    // either way the answers are the stack method's.
    let method = tracer.method_for(&rays, Query::Closest).unwrap();
    assert!(method == raytrail::analysis::order::SORTED_WALK || AUTO_WALKS.contains(&method), "{method}");
    let hits = tracer.intersect(&rays).unwrap();
    assert_eq!(hits, stack_hits(&scene, &rays, Query::Closest));
    assert!(hits.iter().filter(|h| h.is_hit()).count() > rays.len() / 10, "too few hits to compare");
    let camera = primary(&scene, 400, 400);
    assert_eq!(TraceOrder::for_batch(&camera), TraceOrder::AsGiven);
}
