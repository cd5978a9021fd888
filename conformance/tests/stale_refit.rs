//! A refit that leaves something where it was must be caught by the suite's refit check
//! ([`refit_mismatches`]): the binary layout's boxes left from before the move, the 8-wide tree
//! left unrefitted, or no refit at all. Each is traced on the serial backend against a scene
//! prepared afresh from the moved triangles, and must mismatch on the methods that read it and on
//! no other.

use raytrail_conformance::scenes::{breathing, NamedScene};
use raytrail_conformance::suite::{generated_scene, refit_mismatches, GENERATED_RAYS};
use raytrail_conformance::SerialBackend;
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::method::{Bvh2Method, Method, WideMethod};
use raytrail_core::prepared::PreparedScene;
use std::collections::BTreeSet;
use std::sync::Arc;

/// The sphereflake prepared where it is, and moved.
fn before_and_moved() -> (PreparedScene, NamedScene) {
    let named = generated_scene("sphereflake");
    let bvh = SahBuilder::default().build(named.scene.triangles()).unwrap();
    let prepared = PreparedScene::new(&named.scene, bvh, &Method::ALL).unwrap();
    let moved = NamedScene::new("sphereflake breathing", breathing(&named.scene, 1.3).unwrap());
    (prepared, moved)
}

/// The methods with mismatches when `scene` is checked against a fresh preparation of `moved`.
fn mismatched(scene: PreparedScene, moved: &NamedScene) -> BTreeSet<&'static str> {
    let bvh = SahBuilder::default().build(moved.scene.triangles()).unwrap();
    let fresh = Arc::new(PreparedScene::new(&moved.scene, bvh, &Method::ALL).unwrap());
    let found = refit_mismatches(&SerialBackend, Arc::new(scene), fresh, moved, GENERATED_RAYS);
    found.iter().map(|m| m.method.name()).collect()
}

#[test]
fn a_refit_scene_mismatches_nowhere() {
    let (mut scene, moved) = before_and_moved();
    scene.refit(&moved.scene).unwrap();
    assert_eq!(mismatched(scene, &moved), BTreeSet::new());
}

#[test]
fn stale_binary_boxes_are_caught_on_the_methods_that_read_them() {
    let (before, moved) = before_and_moved();
    let mut scene = before.clone();
    scene.refit(&moved.scene).unwrap();
    // The uncle layout's node boxes from before the move; its leaves hold the moved triangles.
    let stale = before.uncles.as_ref().unwrap().nodes.clone();
    scene.uncles.as_mut().unwrap().nodes = stale;
    let found = mismatched(scene, &moved);
    assert!(found.contains(Method::Bvh2(Bvh2Method::Stack).name()), "{found:?}");
    assert!(!found.contains(Method::Wide(WideMethod::BVH8).name()), "{found:?}");
}

#[test]
fn an_unrefitted_wide_tree_is_caught() {
    let (before, moved) = before_and_moved();
    let mut scene = before.clone();
    scene.refit(&moved.scene).unwrap();
    scene.wide8 = before.wide8.clone();
    let found = mismatched(scene, &moved);
    assert!(found.contains(Method::Wide(WideMethod::BVH8).name()), "{found:?}");
    assert!(!found.contains(Method::Bvh2(Bvh2Method::Stack).name()), "{found:?}");
}

#[test]
fn no_refit_at_all_is_caught_on_every_method() {
    let (before, moved) = before_and_moved();
    let found = mismatched(before, &moved);
    assert_eq!(found.len(), Method::ALL.len(), "{found:?}");
}
