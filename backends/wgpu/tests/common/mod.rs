//! What the wgpu test files share: opening the backend or saying in one line why not.

use raytrail_core::Error;
use raytrail_wgpu::{WgpuBackend, REQUIRE_GPU};
use std::io::Write;

/// The backend `make` opens, or `None` with a one-line `SKIPPED <what>` reason on stderr where
/// there is no adapter; under `RAYTRAIL_REQUIRE_GPU=1` a missing adapter fails the test instead.
pub fn open_or_skip(what: &str, make: impl FnOnce() -> Result<WgpuBackend, Error>) -> Option<WgpuBackend> {
    match make() {
        Ok(b) => Some(b),
        Err(e) if std::env::var(REQUIRE_GPU).as_deref() == Ok("1") => panic!("{REQUIRE_GPU}=1 but: {e}"),
        Err(e) => {
            // Past the harness's output capture, so a plain `cargo test` shows why.
            let _ = writeln!(std::io::stderr(), "SKIPPED {what}: {e} (set {REQUIRE_GPU}=1 to make this a failure)");
            None
        }
    }
}
