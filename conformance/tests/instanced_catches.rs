//! The instanced check fails on planted faults: a placement traced where its flattened triangles
//! are not, and a bad instance refused when the scene is made.

use raytrail_conformance::instanced::{closest_disagreements, flatten, instanced_case, instanced_mismatches};
use raytrail_conformance::rays::primary;
use raytrail_conformance::SerialBackend;
use raytrail_core::instance::{trace_instanced, Instance, InstanceHit, InstancedScene, Transform};
use raytrail_core::method::{Bvh2Method, Method};
use raytrail_core::scene::Scene;
use raytrail_core::trace::TraceOptions;
use raytrail_core::Error;

#[test]
fn the_check_passes_on_the_serial_backend() {
    let case = instanced_case();
    let wrong = instanced_mismatches(&SerialBackend, &case, &case.instances);
    assert!(wrong.is_empty(), "{} mismatches, first: {:?}", wrong.len(), &wrong[..wrong.len().min(4)]);
}

#[test]
fn a_wrong_transform_is_caught() {
    let case = instanced_case();
    // The truth moves instance 2 by a twentieth of a unit; the traced scene does not.
    let mut truth = case.instances.clone();
    let moved = Transform::translation([0.05, 0.0, 0.0]).then_after(&truth[2].transform);
    truth[2].transform = moved;
    let wrong = instanced_mismatches(&SerialBackend, &case, &truth);
    assert!(wrong.len() > 10, "a moved instance went unnoticed: {wrong:?}");
}

/// The main job's judgement of closest hits alone (`closest_disagreements`) passes on the true
/// placements and catches the moved one.
#[test]
fn the_closest_hit_judgement_catches_a_wrong_transform() {
    let case = instanced_case();
    let scene = InstancedScene::prepare(&SerialBackend, &case.meshes, &case.instances).expect("prepare");
    let (flat, first) = flatten(&case.scenes, &case.instances, None);
    let rays = primary(&Scene::new(flat.clone()).expect("a flat scene"), 32, 24);
    let mut hits = vec![InstanceHit::MISS; rays.len()];
    let opts = TraceOptions::new(Method::Bvh2(Bvh2Method::Stack));
    trace_instanced(&SerialBackend, &scene, &rays, None, &opts, &mut hits).expect("trace");
    assert_eq!(closest_disagreements(&flat, &first, &case.instances, &rays, &hits), Vec::<String>::new());
    let mut truth = case.instances.clone();
    truth[2].transform = Transform::translation([0.05, 0.0, 0.0]).then_after(&truth[2].transform);
    let (moved, first) = flatten(&case.scenes, &truth, None);
    let wrong = closest_disagreements(&moved, &first, &case.instances, &rays, &hits);
    assert!(wrong.len() > 5, "a moved instance went unnoticed: {wrong:?}");
}

#[test]
fn bad_instances_are_refused_by_name() {
    let case = instanced_case();
    let bad_mesh = [Instance::new(7, Transform::IDENTITY)];
    let flat = [Instance::new(0, Transform::scale([1.0, 0.0, 1.0]))];
    for (instances, what) in [(&bad_mesh[..], "mesh index"), (&flat[..], "invertible")] {
        match InstancedScene::prepare(&SerialBackend, &case.meshes, instances) {
            Err(e @ Error::InvalidInstance { index: 0, .. }) => assert!(e.to_string().contains(what), "{e}"),
            other => panic!("expected an invalid instance, got {other:?}"),
        }
    }
    assert!(matches!(InstancedScene::prepare(&SerialBackend, &case.meshes, &[]), Err(Error::EmptyScene)));
}
