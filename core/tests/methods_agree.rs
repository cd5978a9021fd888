//! Every BVH2 method against the stack method on random scenes, through the core alone (the
//! conformance crate runs the full suite through the backends).

use glam::Vec3;
use raytrail_core::bvh2::traverse::trace_ray;
use raytrail_core::bvh2::{SahBuilder, SahConfig};
use raytrail_core::geometry::Triangle;
use raytrail_core::intersect::Watertight;
use raytrail_core::method::{Bvh2Method, Method, Query};
use raytrail_core::observe::{Both, Counters, Recorder};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::scene::Scene;
use raytrail_core::Ray;

mod common;
use common::{soup, Rng};

fn rays(n: usize, seed: u64) -> Vec<Ray> {
    let mut r = Rng(seed);
    (0..n).map(|_| Ray::new(r.v() * 12.0 - 1.0, r.v() - 0.5, 0.0, f32::INFINITY)).collect()
}

fn check_scene(tris: Vec<Triangle>, config: SahConfig, seed: u64) -> Counters {
    let rays = rays(400, seed);
    check_scene_with(tris, config, &rays)
}

fn check_scene_with(tris: Vec<Triangle>, config: SahConfig, rays: &[Ray]) -> Counters {
    let scene = Scene::new(tris).unwrap();
    let bvh = SahBuilder::new(config).build(scene.triangles()).unwrap();
    let prepared = PreparedScene::new(&scene, bvh, &Method::BVH2).unwrap();
    let mut total = Counters::default();
    for query in [Query::Closest, Query::Any] {
        for (i, ray) in rays.iter().enumerate() {
            let run = |m: Bvh2Method| {
                let mem = prepared.memory(m).unwrap();
                let mut obs = Both(Counters::default(), Recorder::default());
                let hit = match prepared.key_width() {
                    raytrail_core::key::KeyWidth::W32 => {
                        trace_ray::<u32, _, Watertight, _>(m, &mem, prepared.root(m).unwrap(), ray, query, &mut obs)
                    }
                    raytrail_core::key::KeyWidth::W64 => {
                        trace_ray::<u64, _, Watertight, _>(m, &mem, prepared.root(m).unwrap(), ray, query, &mut obs)
                    }
                };
                let layout = prepared.layout(m).unwrap();
                let ids: Vec<u32> = obs.1.nodes.iter().map(|&r| layout.canonical_id(r).unwrap()).collect();
                (hit, ids, obs.0)
            };
            let (stack_hit, stack_ids, _) = run(Bvh2Method::Stack);
            let (_, masked_ids, _) = run(Bvh2Method::StackDisjoint);
            for m in Bvh2Method::ALL {
                let (hit, ids, c) = run(m);
                if m == Bvh2Method::Hash {
                    total.add(&c);
                }
                match query {
                    Query::Closest => assert!(hit.same_as(&stack_hit), "{m} ray {i}: {hit:?} vs {stack_hit:?}"),
                    Query::Any => assert_eq!(hit.is_hit(), stack_hit.is_hit(), "{m} ray {i}"),
                }
                let reference = if m.reference() == Bvh2Method::Stack { &stack_ids } else { &masked_ids };
                assert_eq!(&ids, reference, "{m} ray {i} ({query:?}) enumeration");
            }
        }
    }
    total
}

#[test]
fn all_methods_agree_on_a_soup() {
    let c = check_scene(soup(3000, 1, 0.8), SahConfig::default(), 7);
    assert!(c.hash_lookups() > 0, "the hash must be exercised: {c:?}");
    assert!(c.register.iter().sum::<u64>() > 0);
}

#[test]
fn all_methods_agree_with_single_triangle_leaves() {
    // Leaf size 1 makes deep trees with many leaves as backtracking targets.
    let cfg = SahConfig { max_leaf_size: 1, traversal_cost: 0.1, ..SahConfig::default() };
    check_scene(soup(2000, 2, 0.8), cfg, 8);
}

#[test]
fn all_methods_agree_on_a_deep_tree_with_64_bit_keys() {
    // Triangles at doubling distance and size: a two-bin midpoint split peels off one triangle
    // per level, a chain deeper than 32-bit keys allow.
    let tris: Vec<Triangle> = (0..45)
        .map(|i| {
            let s = 2f32.powi(i);
            Triangle::new(Vec3::new(s, 0.0, 0.0), Vec3::new(s * 1.2, s * 0.3, 0.0), Vec3::new(s, 0.0, s * 0.3))
        })
        .collect();
    let cfg = SahConfig { bins: 2, max_leaf_size: 1, ..SahConfig::default() };
    let scene = Scene::new(tris.clone()).unwrap();
    let depth = SahBuilder::new(cfg).build(scene.triangles()).unwrap().stats().depth;
    assert!(depth > 31, "depth {depth} does not need 64-bit keys");
    // Rays aimed at each triangle from several sides, so deep leaves are reached.
    let mut r = Rng(11);
    let rays: Vec<Ray> = (0..400)
        .map(|i| {
            let t = &tris[i % tris.len()];
            let target = t.centroid();
            let from = target + (r.v() - 0.5) * 4.0 * t.v[0].x;
            Ray::new(from, target - from, 0.0, f32::INFINITY)
        })
        .collect();
    check_scene_with(tris, cfg, &rays);
}
