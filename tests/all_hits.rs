//! All hits along a ray ([`Tracer::intersect_all`]): the lists equal a brute force over every
//! triangle with the same test, bit for bit, under every option; they agree with the exact
//! reference; a ray through a shared edge gets both triangles once; and the brute-force check
//! catches a list that drops one of them.

use raytrail::core::scene::Scene;
use raytrail::{AllHitsOptions, Hit, Ray, Tracer, TracerBuilder, Vec3};
use raytrail_conformance::all_hits::{brute_force_mismatches, exact_mismatches, OPTIONS};
use raytrail_conformance::rays::{ray_sets, RaySetSize};
use raytrail_conformance::scenes::{far_from_origin, shared_edge_grid, sphereflake, triangle_soup};

const SIZE: RaySetSize = RaySetSize { width: 24, height: 18, uniform_count: 256 };

fn scenes() -> Vec<(&'static str, Scene)> {
    vec![
        ("shared_edge_grid", shared_edge_grid(8)),
        ("sphereflake", sphereflake(2)),
        ("triangle_soup", triangle_soup(1500, 7)),
        ("far_from_origin", far_from_origin()),
    ]
}

/// The suite's ray sets for `scene` (camera, shadow, diffuse, uniform, adversarial), in one list.
fn rays(tracer: &Tracer, scene: &Scene) -> Vec<Ray> {
    let mut closest = |rays: &[Ray]| tracer.intersect(rays).unwrap();
    ray_sets(scene, SIZE, &mut closest).into_iter().flat_map(|s| s.rays).collect()
}

#[test]
fn lists_are_a_brute_force_s_bit_for_bit_and_begin_with_the_closest_hit() {
    for (name, scene) in scenes() {
        let tracer = TracerBuilder::default().build_scene(&scene).unwrap();
        let rays = rays(&tracer, &scene);
        let closest = tracer.intersect(&rays).unwrap();
        for options in OPTIONS {
            let lists = tracer.intersect_all(&rays, &options).unwrap();
            let wrong = brute_force_mismatches(tracer.prepared(), &rays, &options, &lists);
            assert!(
                wrong.is_empty(),
                "{name} {options:?}: {} of {} rays differ: {:?}",
                wrong.len(),
                rays.len(),
                &wrong[..wrong.len().min(3)]
            );
            for (i, c) in closest.iter().enumerate() {
                let first = lists.ray(i).unwrap().first().copied().unwrap_or(Hit::MISS);
                if options.max_hits > 0 {
                    assert!(
                        first.same_as(c) || (first.is_refused() && c.is_refused()),
                        "{name} ray {i}: {first:?} vs {c:?}"
                    );
                }
            }
        }
        let lists = tracer.intersect_all(&rays, &OPTIONS[0]).unwrap();
        let hits: usize = lists.iter().map(<[Hit]>::len).sum();
        let many = lists.iter().filter(|l| l.len() > 2).count();
        assert!(
            hits > rays.len() / 4 && many > 0,
            "{name}: {hits} hits, {many} rays with more than two, {} rays",
            rays.len()
        );
    }
}

#[test]
fn lists_agree_with_the_exact_reference() {
    for (name, scene) in scenes().into_iter().filter(|(n, _)| *n != "far_from_origin") {
        let tracer = TracerBuilder::default().build_scene(&scene).unwrap();
        let rays = rays(&tracer, &scene);
        let lists = tracer.intersect_all(&rays, &OPTIONS[0]).unwrap();
        let wrong = exact_mismatches(scene.triangles(), scene.bounds().max_abs(), &rays, &lists);
        assert!(wrong.is_empty(), "{name}: {} disagreements: {:?}", wrong.len(), &wrong[..wrong.len().min(3)]);
        // The check can fail: lists of the same rays cut short at their start (every list empty
        // but for hits at t = 0) lack the hits the exact reference finds.
        let short: Vec<Ray> = rays.iter().map(|r| Ray { tmax: r.tmin, ..*r }).collect();
        let empty = tracer.intersect_all(&short, &OPTIONS[0]).unwrap();
        assert!(!exact_mismatches(scene.triangles(), scene.bounds().max_abs(), &rays, &empty).is_empty(), "{name}");
    }
}

/// The grid's first plane (`z = 0` over `[-1, 1]^2` in 8 x 8 quads of side 1/4), hit straight
/// down through the edge the quads at x in [0, 1/4] and [1/4, 1/2] share, halfway along it.
fn through_a_shared_edge() -> (Tracer, Ray) {
    let tracer = TracerBuilder::default().build_scene(&shared_edge_grid(8)).unwrap();
    (tracer, Ray::new(Vec3::new(0.25, 0.125, 1.0), -Vec3::Z, 0.0, 2.0))
}

#[test]
fn a_ray_through_a_shared_edge_gets_each_side_once_or_merged_one() {
    let (tracer, ray) = through_a_shared_edge();
    let lists = tracer.intersect_all(&[ray], &AllHitsOptions::default()).unwrap();
    let list = lists.ray(0).unwrap();
    assert_eq!(list.len(), 2, "{list:?}");
    assert!(list[0].t == 1.0 && list[1].t == 1.0 && list[0].prim < list[1].prim, "{list:?}");
    assert_eq!(list[0].prim, tracer.intersect_one(&ray).unwrap().unwrap().prim);
    let merged = tracer.intersect_all(&[ray], &AllHitsOptions { merge_equal_t: true, ..Default::default() }).unwrap();
    assert_eq!(merged.ray(0).unwrap(), &list[..1]);
    let cut = tracer.intersect_all(&[ray], &AllHitsOptions { max_hits: 1, ..Default::default() }).unwrap();
    assert!(cut.is_truncated(0) && cut.ray(0).unwrap() == &list[..1]);
}

#[test]
fn a_list_that_drops_a_shared_edge_hit_is_caught() {
    let (tracer, ray) = through_a_shared_edge();
    // The merged list stands in for a walk that loses the second triangle of the edge.
    let dropped = tracer.intersect_all(&[ray], &AllHitsOptions { merge_equal_t: true, ..Default::default() }).unwrap();
    let wrong = brute_force_mismatches(tracer.prepared(), &[ray], &AllHitsOptions::default(), &dropped);
    assert_eq!(wrong.len(), 1, "{wrong:?}");
}

#[test]
fn a_tracer_without_a_wide_tree_says_so() {
    let scene = sphereflake(1);
    let tracer = TracerBuilder::default()
        .method(raytrail::Method::Bvh2(raytrail::core::Bvh2Method::Stack))
        .build_scene(&scene)
        .unwrap();
    let err = tracer.intersect_all(&[Ray::new(Vec3::Z, -Vec3::Z, 0.0, 9.0)], &AllHitsOptions::default()).unwrap_err();
    assert!(err.to_string().contains("a wide tree"), "{err}");
}
