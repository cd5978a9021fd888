//! The conformance suite on the serial reference backend, opted in as any backend would: the
//! smallest backend there is (the core's per-ray entry points, one ray at a time) runs the same
//! cases as the CPU and wgpu backends.

raytrail_conformance::conformance_suite!(raytrail_conformance::SerialBackend);
