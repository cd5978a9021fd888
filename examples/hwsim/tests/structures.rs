//! The kd-tree and wide-BVH lanes change nothing a ray computes: the simulator's hits, work
//! counters and node enumerations equal, ray by ray, those of the core's per-ray traversals that
//! the CPU backend runs (`trace_kd_ray`; `trace_wide_ray` with the `FastKernel`, which
//! `trace_wide_batch` uses; `trace_wide_trail_ray` for the stackless walk), for every simulated kd
//! and wide method, every ray set and several
//! warp widths; and the hits equal the BVH2 stack method's.

use raytrail_conformance::rays::{adversarial, uniform_random, RAY_SEED};
use raytrail_conformance::scenes::sphereflake;
use raytrail_core::intersect::Watertight;
use raytrail_core::kd::traverse::trace_kd_ray;
use raytrail_core::key::KeyWidth;
use raytrail_core::method::WideWalk;
use raytrail_core::method::{KdMethod, Method, Query, WideMethod};
use raytrail_core::observe::{Both, Counters, Recorder};
use raytrail_core::wide::trail::trace_wide_trail_ray;
use raytrail_core::wide::traverse::trace_wide_ray;
use raytrail_core::wide::{FastKernel, WideTree};
use raytrail_core::{Error, Hit, Ray};
use raytrail_hwsim::{reference_hits, simulate, MethodRun, RayKind, Scenario, SimConfig};

/// The kd methods the simulator steps (kd-packet is refused: see the last test).
const KD: [KdMethod; 4] = [KdMethod::Stack, KdMethod::Restart, KdMethod::PushDown, KdMethod::ShortStack];

/// The CPU backend's answer for one ray, with its counters and enumeration.
fn cpu(s: &Scenario, m: Method, ray: &Ray, query: Query) -> (Hit, Both<Counters, Recorder>) {
    let p = &s.prepared;
    let mut obs = Both(Counters::default(), Recorder::default());
    let hit = match m {
        Method::Kd(k) => {
            trace_kd_ray::<_, Watertight, _>(k, &p.kd_memory().unwrap(), &p.kd_root().unwrap(), ray, query, &mut obs)
        }
        Method::Wide(w) if w.walk() == WideWalk::Trail => {
            let (root, (mem, keys)) = (p.wide_root(w).unwrap(), p.wide_keyed(w).unwrap());
            match keys {
                KeyWidth::W32 => {
                    trace_wide_trail_ray::<4, u32, _, Watertight, FastKernel, _>(&mem, root, ray, query, &mut obs)
                }
                KeyWidth::W64 => {
                    trace_wide_trail_ray::<4, u64, _, Watertight, FastKernel, _>(&mem, root, ray, query, &mut obs)
                }
            }
        }
        Method::Wide(w) => {
            let root = p.wide_root(w).unwrap();
            match p.wide_tree(w).unwrap() {
                WideTree::Four(t) => {
                    trace_wide_ray::<4, _, Watertight, FastKernel, _>(&t.memory(), root, ray, query, &mut obs)
                }
                WideTree::Eight(t) => {
                    trace_wide_ray::<8, _, Watertight, FastKernel, _>(&t.memory(), root, ray, query, &mut obs)
                }
            }
        }
        _ => unreachable!("BVH2 methods are checked in lockstep.rs"),
    };
    (hit, obs)
}

/// Checks `m` over `rays` against the CPU backend's traversal, ray by ray.
fn check(s: &Scenario, m: Method, rays: &[Ray], query: Query, warp: usize, stack: &[Hit]) -> MethodRun {
    let cfg = SimConfig { warp, record_enumerations: true, ..SimConfig::new(query) };
    let run = simulate(&s.prepared, m, rays, &cfg).unwrap();
    let mut total = Counters::default();
    for (i, ray) in rays.iter().enumerate() {
        let (want, obs) = cpu(s, m, ray, query);
        let got = run.hits[i];
        assert!(got.same_as(&want), "{m}, ray {i}: lockstep {got:?}, CPU {want:?}");
        if query == Query::Any {
            assert_eq!(got.is_hit(), stack[i].is_hit(), "{m}, ray {i}: occlusion differs from the BVH2 stack method");
        } else {
            assert!(
                got.same_as(&stack[i]),
                "{m}, ray {i}: {got:?} differs from the BVH2 stack method's {:?}",
                stack[i]
            );
        }
        assert_eq!(run.per_ray[i], obs.0, "{m}, ray {i}: work counters differ");
        assert_eq!(run.enumerations[i], obs.1.nodes, "{m}, ray {i}: enumerations differ");
        total.add(&obs.0);
    }
    total.rays = rays.len() as u64;
    let r = &run.report;
    assert_eq!(r.counters, total, "{m}: summed counters");
    assert_eq!(r.lane_steps, total.nodes(), "{m}: one node per step");
    assert_eq!(r.transitions.internal + r.transitions.leaf, total.nodes(), "{m}");
    assert_eq!(r.transitions.restart, total.restarts, "{m}");
    assert!(r.cycles * warp as u64 >= r.lane_steps && r.lane_steps >= r.cycles, "{m}");
    assert!(r.latency_cycles >= r.cycles && r.dependent_reads >= r.lane_steps, "{m}");
    assert_eq!(r.stack_model_mismatches, 0, "{m}: the kd stack model lost the machine");
    run
}

fn check_all(s: &Scenario, rays: &[Ray], query: Query, warp: usize) {
    let stack = reference_hits(&s.prepared, rays, query).unwrap();
    for m in KD.map(Method::Kd) {
        let r = check(s, m, rays, query, warp, &stack).report;
        match m {
            // Pushes, pops and the few pushed off a short stack's bottom (restarts find them).
            Method::Kd(KdMethod::Stack) => assert!(r.stack_pushes >= r.transitions.stack_pop, "{m}"),
            Method::Kd(KdMethod::ShortStack) => assert!(r.peak_stack <= 3, "{m}: {}", r.peak_stack),
            _ => assert_eq!((r.stack_pushes, r.transitions.stack_pop, r.stack_bytes_per_ray()), (0, 0, None), "{m}"),
        }
    }
    for w in WideMethod::ALL.into_iter().filter(|m| !m.walk().shares_walks()) {
        let m = Method::Wide(w);
        let r = check(s, m, rays, query, warp, &stack).report;
        if w.walk() == WideWalk::Trail {
            // No stack. A backtrack tries ancestors up the trail until one has a child left to
            // visit, each through the register or one hash lookup (a displacement entry and at
            // most a cell): at most two reads per level after the node's own.
            assert_eq!((r.stack_pushes, r.transitions.stack_pop, r.stack_bytes_per_ray()), (0, 0, None), "{m}");
            let depth = s.prepared.wide_tree(w).unwrap().stats().depth;
            assert!(r.max_chain >= 1 && r.max_chain <= 1 + 2 * depth, "{m}: {} over depth {depth}", r.max_chain);
            continue;
        }
        if query == Query::Closest {
            // A closest-hit wide traversal ends with an empty stack: every entry is popped
            // (visited or culled).
            assert_eq!(r.stack_pushes, r.transitions.stack_pop, "{m}");
        }
        assert_eq!(r.max_chain, 1, "{m}: one dependent read per step");
    }
}

#[test]
fn kd_and_wide_lanes_match_the_cpu_backend_for_primary_shadow_and_diffuse_rays() {
    for kind in [RayKind::Primary, RayKind::Shadow, RayKind::Diffuse] {
        let s = Scenario::new(sphereflake(2), kind, 32, 24).unwrap();
        assert!(!s.rays.is_empty());
        check_all(&s, &s.rays, kind.query(), 32);
    }
}

#[test]
fn kd_and_wide_lanes_match_for_odd_warps_and_adversarial_rays() {
    let s = Scenario::new(sphereflake(1), RayKind::Primary, 16, 12).unwrap();
    let mut rays = uniform_random(&s.scene, 200, RAY_SEED);
    // NaN, infinite and inverted rays: misses that visit nothing, in lanes next to live ones.
    rays.extend(adversarial(&s.scene, RAY_SEED));
    for warp in [1, 7, 64] {
        check_all(&s, &rays, Query::Closest, warp);
        check_all(&s, &rays, Query::Any, warp);
    }
}

#[test]
fn the_papers_orderings_hold_on_the_model() {
    // The claims the README's table reports, on a smaller scene: Horn et al. (restart and
    // push-down visit more inner nodes than the stack, short-stack nearly as few), Binder & Keller
    // (the hash backtracks in a bounded chain, the walks do not; far less state than a stack),
    // Guthe (a 4-wide tree takes fewer steps, so shorter chains of dependent reads, and its nodes
    // take less memory than the binary tree's).
    let s = Scenario::new(sphereflake(2), RayKind::Primary, 64, 48).unwrap();
    let run = |m: Method| simulate(&s.prepared, m, &s.rays, &SimConfig::new(Query::Closest)).unwrap().report;
    let inner = |m: KdMethod| run(Method::Kd(m)).transitions.internal as f64;
    let (stack, restart, push_down, short) =
        (inner(KdMethod::Stack), inner(KdMethod::Restart), inner(KdMethod::PushDown), inner(KdMethod::ShortStack));
    assert!(restart > 1.5 * stack && push_down > 1.3 * stack && restart > push_down, "{restart} {push_down} {stack}");
    assert!(short >= stack && short < 1.1 * stack, "short-stack {short}, stack {stack}");

    let (bstack, hash, parent) = (
        run(raytrail_core::Bvh2Method::Stack.into()),
        run(raytrail_core::Bvh2Method::Hash.into()),
        run(raytrail_core::Bvh2Method::ParentSibling.into()),
    );
    assert!(hash.max_chain <= 3 && parent.max_chain > hash.max_chain, "{} {}", hash.max_chain, parent.max_chain);
    // A stack takes 4 bytes per level of the tree: 56 on this scene's tree (leaves costed per
    // block of four make it shallower than the 16 levels a per-triangle cost gave), against 16.
    assert!(hash.state_bytes * 3 < bstack.state_bytes, "{} {}", hash.state_bytes, bstack.state_bytes);

    let bvh4 = run(Method::Wide(WideMethod::BVH4));
    assert!(
        bvh4.dependent_reads * 3 < bstack.dependent_reads * 2,
        "{} {}",
        bvh4.dependent_reads,
        bstack.dependent_reads
    );
    // Binder & Keller's trail carried to the 4-wide tree: a fraction of the stack walk's state.
    let trail = run(Method::Wide(WideMethod::BVH4_HASH));
    assert!(trail.state_bytes * 3 < bvh4.state_bytes, "{} {}", trail.state_bytes, bvh4.state_bytes);
    let four = s.prepared.wide_tree(WideMethod::BVH4).unwrap().stats().nodes * 128;
    assert!(four < s.prepared.uncles.as_ref().unwrap().nodes.len() * 64);
}

#[test]
fn kd_packet_is_refused_with_a_typed_error() {
    let s = Scenario::new(sphereflake(1), RayKind::Primary, 4, 4).unwrap();
    let got = simulate(&s.prepared, KdMethod::Packet, &s.rays, &SimConfig::new(Query::Closest));
    assert!(matches!(got.err(), Some(Error::Unsupported { method: "kd-packet", .. })));
}
