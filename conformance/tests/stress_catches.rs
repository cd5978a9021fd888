//! The stress suite can fail: backends that answer wrongly (a miss from inside a closed mesh, a
//! refusal inside the supported range, a refusal the report does not count, the wrong triangle)
//! are caught ray by ray, and the serial backend, traced honestly, passes.

use raytrail_conformance::stress::{all_cases, run_case, StressCase};
use raytrail_conformance::SerialBackend;
use raytrail_core::method::Method;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Report, Trace, TraceOptions};
use raytrail_core::{Error, Hit, Ray};
use std::sync::Arc;

/// The serial backend with its answers changed afterwards by `spoil`.
struct Spoiled(fn(&mut Hit, &mut Report));

impl Trace for Spoiled {
    type Prepared = Arc<PreparedScene>;
    fn name(&self) -> &str {
        "spoiled"
    }
    fn supports(&self, method: Method) -> bool {
        SerialBackend.supports(method)
    }
    fn prepare(&self, scene: Arc<PreparedScene>) -> Result<Self::Prepared, Error> {
        SerialBackend.prepare(scene)
    }
    fn trace(&self, s: &Self::Prepared, rays: &[Ray], o: &TraceOptions, hits: &mut [Hit]) -> Result<Report, Error> {
        let mut report = SerialBackend.trace(s, rays, o, hits)?;
        for h in hits.iter_mut() {
            (self.0)(h, &mut report);
        }
        Ok(report)
    }
}

fn case(name: &str) -> StressCase {
    all_cases().expect("cases").into_iter().find(|c| c.name.starts_with(name)).expect("case")
}

fn disagreements(backend: &impl Trace, c: &StressCase) -> Vec<usize> {
    run_case(backend, c).expect("runs").iter().map(|t| t.disagreeing).collect()
}

#[test]
fn honest_answers_pass() {
    for name in ["shared vertices", "teapot, origins 1e8", "scaled by 1e30, from inside", "range edge: origins 1e10"] {
        assert!(disagreements(&SerialBackend, &case(name)).iter().all(|&d| d == 0), "{name}");
    }
}

#[test]
fn spoiled_answers_fail_for_every_method() {
    let closed = case("shared vertices");
    let n = closed.rays.len();
    let each = |b: &Spoiled, c: &StressCase, at_least: usize| {
        let d = disagreements(b, c);
        assert!(d.len() == Method::ALL.len() && d.iter().all(|&x| x >= at_least), "{d:?}");
    };
    // A miss through a closed mesh (a crack).
    each(&Spoiled(|h, _| *h = Hit::MISS), &closed, n);
    // A refusal inside the supported range.
    each(
        &Spoiled(|h, r| {
            *h = Hit::REFUSED;
            r.refused += 1
        }),
        &closed,
        n,
    );
    // The wrong triangle.
    each(&Spoiled(|h, _| h.prim = (h.prim + 7) % 320), &closed, n / 2);
    // A refused ray the report does not count.
    let outside = case("range edge: origins 1e10");
    each(&Spoiled(|_, r| r.refused = 0), &outside, 1);
    // A far ray answered (with a miss) instead of refused.
    each(&Spoiled(|h, _| *h = Hit::MISS), &outside, outside.rays.len());
}
