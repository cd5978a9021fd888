//! The kernels' arithmetic against the CPU's on the adapter wgpu finds: correctly rounded
//! division and products fenced against contraction, bit for bit over a million samples, in the
//! kernel form the backend picks and, separately, as SPIR-V asking for preserved subnormals.
//! Skipped with a one-line reason without an adapter, unless `RAYTRAIL_REQUIRE_GPU=1`.

mod common;

use raytrail_wgpu::{KernelForm, WgpuBackend};

/// The backend in `form`, or `None` (with the reason on stderr) where there is no adapter.
fn open(form: KernelForm) -> Option<WgpuBackend> {
    common::open_or_skip("the wgpu numerics probe", || WgpuBackend::with_kernel_form(form))
}

fn check(backend: &WgpuBackend) {
    let p = backend.probe_numerics(1 << 20).expect("probe");
    eprintln!("{}: {}", backend.adapter(), p.summary());
    assert!(p.samples >= 1 << 20);
    assert_eq!(p.div_rn_mismatches, 0, "div_rn is not correctly rounded: {}", p.summary());
    assert_eq!(p.fenced_mismatches, 0, "fenced products differ from the CPU: {}", p.summary());
}

#[test]
fn kernel_arithmetic_matches_the_cpu_bit_for_bit() {
    if let Some(b) = open(KernelForm::Auto) {
        check(&b);
    }
}

/// The SPIR-V path (naga's output plus `DenormPreserve`) on every adapter with shader passthrough,
/// so that CI's lavapipe, which keeps subnormals without being asked, runs it too.
#[test]
fn spirv_kernels_match_the_cpu_bit_for_bit() {
    if let Some(b) = open(KernelForm::Spirv) {
        check(&b);
    }
}
