//! The CPU backend's x86_64 SIMD paths, chosen at run time where the processor has AVX2, one
//! file per walk over one shared child kernel:
//! - [`child_kernel`]: an 8-wide node's boxes in one 256-bit operation per plane, hit children
//!   ordered by rank (every walk's box tests);
//! - [`single_ray`]: the stack and the (stackless) trail walks of one ray at a time;
//! - [`stream`]: the Barringer-style ray-stream walk;
//! - [`packet`] with [`packet_begin`] and [`packet_leaf`]: the wide packet walk, its lanes made
//!   eight rays at a time and its leaves tested with the rays in the lanes; [`lanes`] holds the
//!   lane helpers they share.
//!
//! Each walk is compiled for AVX2 and for the bit instructions every AVX2 processor has (BMI1,
//! BMI2, LZCNT, POPCNT): without them a mask's `count_ones` was a multiply sequence on the path
//! to every node's order, and each `trailing_zeros` a branchy `bsf` (1.01-1.03 on most ray sets;
//! `docs/notes/*-benchmarks-leaf-blocks.md`, "Triangle blocks that carry their primitive ids").
//! Every answer and every order is the portable kernels' bit for bit; each file's tests hold it
//! to that on adversarial values.

pub(crate) mod child_kernel;
pub(crate) mod lanes;
pub(crate) mod packet;
pub(crate) mod packet_begin;
pub(crate) mod packet_leaf;
pub(crate) mod single_ray;
pub(crate) mod stream;

/// Whether this processor runs the AVX2 path: AVX2 and the bit instructions the path is compiled
/// for with it (every AVX2 processor has them; the check costs nothing per ray).
pub(crate) fn available() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("bmi1")
        && std::arch::is_x86_feature_detected!("bmi2")
        && std::arch::is_x86_feature_detected!("lzcnt")
        && std::arch::is_x86_feature_detected!("popcnt")
}

/// For a test of an AVX2 path: whether this processor lacks AVX2, in which case the test is said
/// to be skipped (`what`: the test's name in the message) and should return.
#[cfg(test)]
pub(crate) fn lacks_avx2_for(what: &str) -> bool {
    let lacks = !available();
    if lacks {
        eprintln!("SKIPPED the AVX2 {what} test: this processor has no AVX2");
    }
    lacks
}
