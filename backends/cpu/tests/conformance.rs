//! The conformance suite on the CPU backend: every method, closest and any hit, every ray set, on
//! every generated scene and every mesh of the scenes folder, against each method's reference and
//! ray by ray against the serial reference backend.

raytrail_conformance::conformance_suite!(raytrail_cpu::CpuBackend::new());
