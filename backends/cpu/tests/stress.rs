//! The stress suite (issue 15) on the CPU backend: every method against the exact reference.

raytrail_conformance::stress_suite!(raytrail_cpu::CpuBackend::new());
