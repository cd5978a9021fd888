//! Runs a stress case on a backend: every method, closest hit, each ray judged against the exact
//! reference.

use super::cases::{all_cases, StressCase};
use crate::exact::{closest_hit, judge, Judgement, Tolerance};
use crate::suite::REQUIRE_GPU;
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::method::Method;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::scene::Scene;
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::Hit;
use std::fmt::{self, Display};
use std::sync::Arc;

/// One method's results on one case.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tally {
    /// The method's name.
    pub method: &'static str,
    /// Rays traced.
    pub rays: usize,
    /// Exact answers.
    pub exact: usize,
    /// Answers within the tolerance ([`crate::exact::verdict`]).
    pub near: usize,
    /// Refused rays.
    pub refused: usize,
    /// Wrong answers.
    pub disagreeing: usize,
    /// What was wrong, for the first few (empty when none).
    pub failures: Vec<String>,
}

impl Tally {
    /// Rays that agree with the exact reference (exact or near).
    pub fn agreeing(&self) -> usize {
        self.exact + self.near
    }
}

impl Display for Tally {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:<18} rays {:>5}  agree {:>5} (exact {:>5}, near {:>3})  refused {:>5}  disagree {:>4}",
            self.method,
            self.rays,
            self.agreeing(),
            self.exact,
            self.near,
            self.refused,
            self.disagreeing
        )
    }
}

/// A stress case that could not be run: its scene, tree or trace failed.
#[derive(Debug)]
pub struct CaseError {
    /// The case's name.
    pub case: String,
    /// The method whose trace failed, or `None` where preparing the case did.
    pub method: Option<&'static str>,
    /// What failed.
    pub error: raytrail_core::Error,
}

impl core::fmt::Display for CaseError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.method {
            Some(m) => write!(f, "{}, {m}: {}", self.case, self.error),
            None => write!(f, "{}: {}", self.case, self.error),
        }
    }
}

impl std::error::Error for CaseError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.error)
    }
}

/// Traces `case` with every method on `backend` and judges every ray; the tallies, one per
/// method, with any breach of the case's rules counted as a disagreement.
pub fn run_case<B: Trace>(backend: &B, case: &StressCase) -> Result<Vec<Tally>, CaseError> {
    let failed = |error| CaseError { case: case.name.clone(), method: None, error };
    let scene = Scene::new(case.triangles.clone()).map_err(failed)?;
    let bvh = SahBuilder::default().build(scene.triangles()).map_err(failed)?;
    let prepared = PreparedScene::new(&scene, bvh, &Method::ALL).map_err(failed)?;
    let prepared = backend.prepare(Arc::new(prepared)).map_err(failed)?;
    let tol = Tolerance::for_scene(scene.bounds().max_abs());
    let exact: Vec<_> = case.rays.iter().map(|r| closest_hit(r, &case.triangles)).collect();
    let mut out = Vec::new();
    for method in Method::ALL {
        let mut hits = vec![Hit::MISS; case.rays.len()];
        let report = backend
            .trace(&prepared, &case.rays, &TraceOptions::new(method), &mut hits)
            .map_err(|error| CaseError { case: case.name.clone(), method: Some(method.name()), error })?;
        let mut t = Tally { method: method.name(), rays: case.rays.len(), ..Tally::default() };
        let fail = |t: &mut Tally, why: String| {
            t.disagreeing += 1;
            if t.failures.len() < 4 {
                t.failures.push(why);
            }
        };
        for (i, (ray, hit)) in case.rays.iter().zip(&hits).enumerate() {
            match judge(ray, &case.triangles, &exact[i], hit, tol, case.must_hit) {
                Judgement::Exact if !case.must_refuse => t.exact += 1,
                Judgement::Near if !case.must_refuse => t.near += 1,
                Judgement::Refused if case.may_refuse => t.refused += 1,
                Judgement::Refused => fail(&mut t, format!("ray {i} {ray:?}: refused inside the supported range")),
                Judgement::Disagree(why) => fail(&mut t, format!("ray {i} {ray:?}: {why}")),
                _ => fail(&mut t, format!("ray {i} {ray:?}: answered {hit:?} outside the supported range")),
            }
        }
        let marked = hits.iter().filter(|h| h.is_refused()).count();
        if report.refused != marked {
            fail(&mut t, format!("the report counts {} refused rays, the hits mark {marked}", report.refused));
        }
        out.push(t);
    }
    Ok(out)
}

/// Runs every case on `backend`, prints the tallies, and panics naming every disagreement.
pub fn run_all<B: Trace>(backend: &B) {
    let cases = all_cases().unwrap_or_else(|e| panic!("the stress cases cannot be made: {e}"));
    let mut failures = Vec::new();
    for case in &cases {
        let tallies = run_case(backend, case).unwrap_or_else(|e| panic!("{e}"));
        eprintln!("{} ({} triangles):", case.name, case.triangles.len());
        for t in &tallies {
            eprintln!("  {t}");
            if t.disagreeing > 0 {
                failures.push(format!(
                    "{} / {}: {} disagree, e.g. {}",
                    case.name,
                    t.method,
                    t.disagreeing,
                    t.failures.join("; ")
                ));
            }
        }
    }
    assert!(!cases.is_empty());
    if !failures.is_empty() {
        panic!(
            "\n{} DISAGREEMENTS with the exact reference on {}:\n{}",
            failures.len(),
            backend.name(),
            failures.join("\n")
        );
    }
}

/// [`run_all`] on a backend whose constructor may fail (a GPU's): a failure skips with a printed
/// reason, or fails the test when `RAYTRAIL_REQUIRE_GPU=1`.
pub fn run_all_or_skip<B: Trace, E: Display>(make: impl FnOnce() -> Result<B, E>) {
    match make() {
        Ok(b) => run_all(&b),
        Err(e) if std::env::var(REQUIRE_GPU).as_deref() == Ok("1") => {
            panic!("{REQUIRE_GPU}=1 but the backend is unavailable: {e}")
        }
        Err(e) => eprintln!("SKIPPED the stress suite: {e} (set {REQUIRE_GPU}=1 to make this a failure)"),
    }
}
