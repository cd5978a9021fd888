//! The stress suite: cases that drive the numerics to their limits, each traced by every method
//! and judged ray by ray against the exact reference ([`crate::exact`]).
//!
//! Every method must give the exact answer (or one within its tolerance, see
//! [`crate::exact::verdict`]) or refuse the ray explicitly ([`raytrail_core::Hit::REFUSED`],
//! counted in the `Report`). A backend opts in with one line, as for the conformance suite:
//! `raytrail_conformance::stress_suite!(MyBackend::new());`. The command line prints the same
//! tallies (`raytrail stress`).

pub mod cases;
pub mod run;

pub use cases::{all_cases, case_names, StressCase};
pub use run::{run_case, CaseError, Tally};

/// Defines one `#[test]` per stress case for a backend (as `conformance_suite!` does, `try` for a
/// constructor returning a `Result`; a missing GPU adapter skips unless `RAYTRAIL_REQUIRE_GPU=1`).
#[macro_export]
macro_rules! stress_suite {
    (try $make:expr) => {
        #[test]
        fn stress_suite() {
            $crate::stress::run::run_all_or_skip(|| $make);
        }
    };
    ($make:expr) => {
        #[test]
        fn stress_suite() {
            $crate::stress::run::run_all(&$make);
        }
    };
}
