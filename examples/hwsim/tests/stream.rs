//! The stream model changes nothing a ray computes: each ray's hit on the model (its packet's
//! leaves, one ray at a time) equals the CPU backend's stream method's for the same rays, and the
//! stack method's, closest and any hit, with sorted and unsorted packets, at several warp widths;
//! with the method's own (sorted) packets the model's triangle tests are the backend's; and the
//! model's work figures hold together.

use raytrail_core::method::{Method, Query, StreamMethod};
use raytrail_core::trace::{Record, Trace, TraceOptions};
use raytrail_core::Hit;
use raytrail_cpu::CpuBackend;
use raytrail_hwsim::stream_lanes::{simulate_stream, Packing};
use raytrail_hwsim::{reference_hits, RayKind, Scenario};
use std::sync::Arc;

#[test]
fn the_model_gives_the_backends_hits() {
    let cpu = CpuBackend::new();
    for kind in [RayKind::Primary, RayKind::Shadow, RayKind::Diffuse] {
        let s = Scenario::new(raytrail_conformance::scenes::sphereflake(2), kind, 48, 36).expect("scenario");
        let scene = cpu.prepare(Arc::new(s.prepared.clone())).expect("prepare");
        for query in Query::ALL {
            let mut backend = vec![Hit::MISS; s.rays.len()];
            let opts = TraceOptions::new(Method::Stream(StreamMethod::Frustum8)).query(query).record(Record::Counters);
            let counted = cpu.trace(&scene, &s.rays, &opts, &mut backend).expect("trace").counters.expect("counters");
            let stack = reference_hits(&s.prepared, &s.rays, query).expect("stack");
            for packing in [Packing::Sorted, Packing::InputOrder] {
                for warp in [1, 7, 32] {
                    let (report, hits) = simulate_stream(&s.prepared, &s.rays, query, warp, packing).expect("model");
                    for (i, ((m, b), r)) in hits.iter().zip(&backend).zip(&stack).enumerate() {
                        let same = |x: &Hit, y: &Hit| match query {
                            Query::Closest => x.same_as(y),
                            Query::Any => x.is_hit() == y.is_hit(),
                        };
                        assert!(
                            same(m, b) && same(m, r),
                            "{kind:?} {query:?} {packing:?} warp {warp}: ray {i}: model {m:?}, cpu {b:?}, stack {r:?}"
                        );
                    }
                    assert!(report.warps >= report.packets && report.rays == s.rays.len());
                    if packing == Packing::Sorted {
                        // The same work as the backend's: every ray's triangle tests, summed.
                        assert_eq!(
                            report.triangle_tests, counted.primitive_tests,
                            "{kind:?} {query:?}: triangle tests"
                        );
                    }
                    assert!(report.triangle_steps <= report.leaf_steps);
                    assert!(report.active_lane_steps >= report.triangle_steps);
                    assert!(report.active_lane_steps <= report.triangle_steps * warp as u64);
                }
            }
        }
    }
    // The comparison above is not over nothing: the stack method hits on these rays.
    let s = Scenario::new(raytrail_conformance::scenes::sphereflake(2), RayKind::Primary, 48, 36).expect("scenario");
    let stack = reference_hits(&s.prepared, &s.rays, Query::Closest).expect("stack");
    assert!(stack.iter().any(Hit::is_hit), "no primary ray hits");
}
