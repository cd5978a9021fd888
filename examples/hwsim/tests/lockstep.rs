//! Lockstep changes nothing a ray computes: the simulator's hits, work counters and node
//! enumerations equal those of `trace_ray` ray by ray, for every method, key width and warp width.

use raytrail_conformance::rays::{adversarial, uniform_random, RAY_SEED};
use raytrail_conformance::scenes::{degenerate_stack, sphereflake, DEGENERATE_STACK_LAYERS, SCENE_SEED};
use raytrail_core::bvh2::traverse::trace_ray;
use raytrail_core::intersect::Watertight;
use raytrail_core::key::{Key, KeyWidth};
use raytrail_core::method::{Bvh2Method, Query};
use raytrail_core::observe::{Both, Counters, Recorder};
use raytrail_core::Ray;
use raytrail_hwsim::{reference_hits, simulate, RayKind, Scenario, SimConfig};

/// Checks every method over `rays` against `trace_ray`, ray by ray.
fn check<K: Key>(s: &Scenario, rays: &[Ray], query: Query, warp: usize) {
    assert_eq!(s.prepared.key_width(), K::WIDTH);
    let stack = reference_hits(&s.prepared, rays, query).unwrap();
    for m in Bvh2Method::ALL {
        let cfg = SimConfig { warp, record_enumerations: true, ..SimConfig::new(query) };
        let run = simulate(&s.prepared, m, rays, &cfg).unwrap();
        let (mem, root) = (s.prepared.memory(m).unwrap(), s.prepared.root(m).unwrap());
        let mut total = Counters::default();
        for (i, ray) in rays.iter().enumerate() {
            let mut obs = Both(Counters::default(), Recorder::default());
            let want = trace_ray::<K, _, Watertight, _>(m, &mem, root, ray, query, &mut obs);
            let got = run.hits[i];
            assert!(got.same_as(&want), "{m}, ray {i}: lockstep {got:?}, trace_ray {want:?}");
            if query == Query::Any {
                assert_eq!(got.is_hit(), stack[i].is_hit(), "{m}, ray {i}: occlusion differs from the stack method");
            } else {
                assert!(got.same_as(&stack[i]), "{m}, ray {i}: {got:?} differs from the stack method's {:?}", stack[i]);
            }
            assert_eq!(run.per_ray[i], obs.0, "{m}, ray {i}: work counters differ");
            assert_eq!(run.enumerations[i], obs.1.nodes, "{m}, ray {i}: enumerations differ");
            total.add(&obs.0);
        }
        total.rays = rays.len() as u64;
        let r = &run.report;
        assert_eq!(r.counters, total, "{m}: summed counters");
        // One node per step; every lane-step is in exactly one cycle.
        assert_eq!(r.lane_steps, total.nodes(), "{m}");
        assert_eq!(r.transitions.internal + r.transitions.leaf, total.nodes(), "{m}");
        assert!(r.cycles * warp as u64 >= r.lane_steps && r.lane_steps >= r.cycles, "{m}");
        assert!(r.latency_cycles >= r.cycles, "{m}");
        assert_eq!(r.warps, rays.len().div_ceil(warp), "{m}");
        if m == Bvh2Method::Stack && query == Query::Closest {
            // A closest-hit stack traversal ends with an empty stack: every push is popped.
            assert_eq!(r.postponed, r.transitions.stack_pop, "{m}");
        }
    }
}

#[test]
fn lockstep_matches_trace_ray_for_primary_shadow_and_diffuse_rays() {
    for kind in [RayKind::Primary, RayKind::Shadow, RayKind::Diffuse] {
        let s = Scenario::new(sphereflake(2), kind, 32, 24).unwrap();
        assert!(!s.rays.is_empty());
        check::<u32>(&s, &s.rays, kind.query(), 32);
    }
}

#[test]
fn lockstep_matches_trace_ray_for_odd_warps_and_adversarial_rays() {
    let s = Scenario::new(sphereflake(1), RayKind::Primary, 16, 12).unwrap();
    let mut rays = uniform_random(&s.scene, 200, RAY_SEED);
    // NaN, infinite and inverted rays: misses that visit nothing, in lanes next to live ones.
    rays.extend(adversarial(&s.scene, RAY_SEED));
    for warp in [1, 7, 64] {
        check::<u32>(&s, &rays, Query::Closest, warp);
        check::<u32>(&s, &rays, Query::Any, warp);
    }
}

#[test]
fn sixty_four_bit_keys_are_simulated_too() {
    let s = Scenario::new(degenerate_stack(DEGENERATE_STACK_LAYERS, SCENE_SEED), RayKind::Primary, 16, 12).unwrap();
    assert_eq!(s.prepared.key_width(), KeyWidth::W64);
    let mut rays = s.rays.clone();
    rays.extend(uniform_random(&s.scene, 100, RAY_SEED));
    check::<u64>(&s, &rays, Query::Closest, 32);
}

#[test]
fn a_warp_of_one_lane_is_always_fully_active() {
    let s = Scenario::new(sphereflake(1), RayKind::Primary, 16, 12).unwrap();
    let run =
        simulate(&s.prepared, Bvh2Method::Hash, &s.rays, &SimConfig { warp: 1, ..SimConfig::new(Query::Closest) })
            .unwrap();
    let r = &run.report;
    assert_eq!(r.cycles, r.lane_steps);
    // Rays that miss the root's children still take one step, so every ray takes at least one.
    assert_eq!(r.simt_efficiency(), 1.0);
}

#[test]
fn stackless_methods_move_no_stack_bytes_and_hold_less_state() {
    let s = Scenario::new(sphereflake(1), RayKind::Primary, 16, 12).unwrap();
    let cfg = SimConfig { record_timeline: true, ..SimConfig::new(Query::Closest) };
    let stack = simulate(&s.prepared, Bvh2Method::Stack, &s.rays, &cfg).unwrap().report;
    assert!(stack.stack_bytes_per_ray().unwrap() > 0.0);
    for m in [
        Bvh2Method::ParentSibling,
        Bvh2Method::Uncle,
        Bvh2Method::Hash,
        Bvh2Method::HashDisjoint,
        Bvh2Method::HashResume,
    ] {
        let run = simulate(&s.prepared, m, &s.rays, &cfg).unwrap();
        assert_eq!(run.report.stack_bytes_per_ray(), None, "{m}");
        assert_eq!(run.report.transitions.stack_pop, 0, "{m}");
        assert!(run.report.state_bytes < stack.state_bytes, "{m}");
        // The timeline is the slowest warp: as many rows as that warp took cycles, one symbol a lane.
        assert!(!run.timeline.is_empty() && run.timeline.iter().all(|c| c.lanes.len() == 32), "{m}");
    }
}
