//! The single-ray walks compiled for AVX2 with [`AvxKernel`]: the stack walk and the trail
//! (stackless) walk, a batch at a time.

use super::child_kernel::AvxKernel;
use raytrail_core::intersect::TriangleTest;
use raytrail_core::key::Key;
use raytrail_core::method::Query;
use raytrail_core::observe::Observer;
use raytrail_core::wide::keyed::WideKeyedMemory;
use raytrail_core::wide::trail::trace_wide_trail_batch;
use raytrail_core::wide::traverse::{trace_wide_batch, WideRoot};
use raytrail_core::wide::WideMemory;
use raytrail_core::{Hit, Ray};

/// [`trace_wide_batch`] with [`AvxKernel`], compiled for AVX2.
///
/// # Safety
/// The processor must run the AVX2 path ([`available`]).
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
pub(crate) unsafe fn trace_batch<const W: usize, M: WideMemory<W> + ?Sized, T: TriangleTest, O: Observer>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    obs: &mut O,
) {
    trace_wide_batch::<W, M, T, AvxKernel, O>(mem, root, rays, hits, query, obs);
}

/// [`trace_wide_trail_batch`] (the stackless trail walk) with [`AvxKernel`], compiled for
/// AVX2.
///
/// # Safety
/// The processor must run the AVX2 path ([`available`]).
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
pub(crate) unsafe fn trace_trail_batch<
    const W: usize,
    K: Key,
    M: WideKeyedMemory<W> + ?Sized,
    T: TriangleTest,
    O: Observer,
>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    obs: &mut O,
) {
    trace_wide_trail_batch::<W, K, M, T, AvxKernel, O>(mem, root, rays, hits, query, obs);
}
