//! A known accuracy gap, kept as a test that runs on request (`cargo test -p raytrail-conformance
//! --test vertex_aimed_far -- --ignored`) until it passes: a ray aimed exactly at a vertex of the
//! teapot from about three times the scene's magnitude away (inside `FAR_FACTOR`, so not moved
//! up) is answered with face 4909 at t = 0.9999986 by every method, where the exact reference
//! finds that the float32 ray passes outside 4909 by about twice the suite's tolerance and first
//! hits face 7 at t = 1.0184. Started from halfway along the same ray, the answer is exact. The
//! ray grazes 4909 (cosine 0.0012 with its normal), so an ulp across the ray is ~6e-5 in the
//! plane, where the verdict measures its tolerance: the likely fix is in the verdict, not the
//! test. Found by the Python tests' exact judgement (python/tests/test_trimesh.py).

use raytrail_conformance::exact::{judge, ExactScene, Judgement, Tolerance};
use raytrail_conformance::paths::load_mesh_scene;
use raytrail_conformance::SerialBackend;
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::glam::Vec3;
use raytrail_core::method::{Bvh2Method, Method};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::{Hit, Ray};
use std::sync::Arc;

#[test]
#[ignore = "known accuracy gap: a vertex-aimed ray from ~3x the scene's size lands outside the tolerance"]
fn a_vertex_aimed_ray_from_three_scene_sizes_away_is_answered_within_the_tolerance() {
    let scene = load_mesh_scene("teapot.obj").expect("the teapot ships in the crate").scene;
    let exact = ExactScene::new(scene.triangles().to_vec());
    let method = Method::Bvh2(Bvh2Method::Stack);
    let bvh = SahBuilder::default().build(scene.triangles()).unwrap();
    let prepared = SerialBackend.prepare(Arc::new(PreparedScene::new(&scene, bvh, &[method]).unwrap())).unwrap();
    let (o, d) = (Vec3::new(-9.9667635, 4.953761, 0.5745586), Vec3::new(10.941785, -2.479361, -1.2901136));
    for start in [0.5f32, 0.0] {
        let ray = Ray::new(o + d * start, d, 0.0, f32::INFINITY);
        let mut hit = [Hit::MISS];
        SerialBackend.trace(&prepared, &[ray], &TraceOptions::new(method), &mut hit).unwrap();
        let verdict = judge(
            &ray,
            exact.triangles(),
            &exact.closest_hit(&ray),
            &hit[0],
            Tolerance::for_scene(scene.bounds().max_abs()),
            false,
        );
        assert!(
            matches!(verdict, Judgement::Exact | Judgement::Near),
            "from {start} along the ray: {:?} judged {verdict:?}",
            hit[0]
        );
    }
}
