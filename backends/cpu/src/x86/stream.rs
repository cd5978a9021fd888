//! The ray-stream walk compiled for AVX2 with [`AvxKernel`].

use super::child_kernel::AvxKernel;
use raytrail_core::intersect::TriangleTest;
use raytrail_core::method::Query;
use raytrail_core::observe::Observer;
use raytrail_core::wide::ray_stream::trace_wide_streams;
use raytrail_core::wide::traverse::WideRoot;
use raytrail_core::wide::WideMemory;
use raytrail_core::{Hit, Ray};

/// [`trace_wide_streams`] (streams of rays) with [`AvxKernel`], compiled for AVX2.
///
/// # Safety
/// The processor must run the AVX2 path ([`available`]).
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
pub(crate) unsafe fn trace_streams<
    const W: usize,
    M: WideMemory<W> + ?Sized,
    T: TriangleTest,
    O: Observer + Default,
>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    done: impl FnMut(usize, O),
) {
    trace_wide_streams::<W, M, T, AvxKernel, O>(mem, root, rays, hits, query, done);
}
