//! The wide-BVH methods' loop for one chunk, monomorphized per width x memory x triangle test x
//! recording, with the fast child kernel (SIMD box tests, the sorting network), in the AVX2 loop
//! where the processor has AVX2; the packet method's loop over the chunk's packets and the stream
//! method's over its streams likewise. The memory prefetches hit children where that pays (a large
//! tree, incoherent rays, any-hit ones only in packets and streams: [`worth_prefetching`]; in the
//! packet loop, only the subtrees handed over to single rays prefetch).

use crate::chunk::Chunk;
use crate::record::{record, with_test, Independent, RayLoop, Shared, SharedWalks, WithTest};
use core::marker::PhantomData;
use raytrail_core::intersect::TriangleTest;
use raytrail_core::method::WideWalk;
use raytrail_core::method::{Method, Query, WideMethod};
use raytrail_core::observe::{Counters, Observer};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::TraceOptions;
use raytrail_core::wide::packet::{trace_wide_packets, ReferencePacketKernel};
use raytrail_core::wide::ray_stream::trace_wide_streams;
use raytrail_core::wide::traverse::{trace_wide_batch, WideRoot};
use raytrail_core::wide::{worth_prefetching, FastKernel, PrefetchingMemory, WideMemory, WideSliceMemory, WideTree};
use raytrail_core::{Error, Hit, Ray};

/// Traces one chunk with `method`, one ray at a time or, for a packet method, in wide packets;
/// returns its counters. The chunk must not split the packet grouping's chunks.
pub(crate) fn trace_chunk(
    scene: &PreparedScene,
    method: WideMethod,
    opts: &TraceOptions,
    chunk: Chunk<'_>,
) -> Result<Counters, Error> {
    if method.walk() == WideWalk::Trail {
        return crate::trail::trace_chunk(scene, method, opts, chunk);
    }
    let root = scene.wide_root(method)?;
    match scene.wide_tree(method)? {
        WideTree::Four(t) => WideRun { scene, method, opts, root }.go(t.memory(), chunk),
        WideTree::Eight(t) => WideRun { scene, method, opts, root }.go(t.memory(), chunk),
    }
}

struct WideRun<'a> {
    scene: &'a PreparedScene,
    method: WideMethod,
    opts: &'a TraceOptions,
    root: WideRoot,
}

impl WideRun<'_> {
    /// Prefetches hit children where that pays ([`worth_prefetching`]).
    fn go<const W: usize>(&self, mem: WideSliceMemory<'_, W>, chunk: Chunk<'_>) -> Result<Counters, Error> {
        let bytes = core::mem::size_of_val(mem.nodes) + core::mem::size_of_val(mem.blocks);
        if worth_prefetching(bytes, chunk.rays, self.opts.query, self.method.walk().shares_walks()) {
            self.test(&PrefetchingMemory(mem), chunk)
        } else {
            self.test(&mem, chunk)
        }
    }

    fn test<const W: usize, M: WideMemory<W>>(&self, mem: &M, chunk: Chunk<'_>) -> Result<Counters, Error> {
        with_test(self.opts.triangle_test, ByTest::<W, M> { run: self, mem, chunk })
    }
}

/// A [`WideRun`] over memory `M`, waiting for its triangle test.
struct ByTest<'r, 'm, 'c, const W: usize, M> {
    run: &'r WideRun<'r>,
    mem: &'m M,
    chunk: Chunk<'c>,
}

impl<const W: usize, M: WideMemory<W>> WithTest for ByTest<'_, '_, '_, W, M> {
    type Output = Result<Counters, Error>;
    fn with<T: TriangleTest>(self) -> Self::Output {
        let ByTest { run, mem, chunk } = self;
        let (root, query, method) = (run.root, run.opts.query, run.method);
        let (scene, record_what) = (run.scene, run.opts.record);
        if method.walk().shares_walks() {
            let walks = SharedWalk::<W, M, T> {
                mem,
                root,
                query,
                streams: method.walk() == WideWalk::RayLists,
                test: PhantomData,
            };
            return record(scene, Method::Wide(method), record_what, chunk, &Shared(&walks));
        }
        let stack = StackBatch::<W, M, T> { mem, root, query, test: PhantomData };
        record(scene, Method::Wide(method), record_what, chunk, &Independent(&stack))
    }
}

/// The packet loop ([`packets`]) or, with `streams`, the stream loop ([`streams`]).
struct SharedWalk<'m, const W: usize, M, T> {
    mem: &'m M,
    root: WideRoot,
    query: Query,
    streams: bool,
    test: PhantomData<T>,
}

impl<const W: usize, M: WideMemory<W>, T: TriangleTest> SharedWalks for SharedWalk<'_, W, M, T> {
    fn trace<O: Observer + Default>(&self, rays: &[Ray], hits: &mut [Hit], done: &mut impl FnMut(usize, O)) {
        if self.streams {
            streams::<W, M, T, O>(self.mem, self.root, rays, hits, self.query, done);
        } else {
            packets::<W, M, T, O>(self.mem, self.root, rays, hits, self.query, done);
        }
    }
}

/// The stack traversal's loop ([`batch`]).
struct StackBatch<'m, const W: usize, M, T> {
    mem: &'m M,
    root: WideRoot,
    query: Query,
    test: PhantomData<T>,
}

impl<const W: usize, M: WideMemory<W>, T: TriangleTest> RayLoop for StackBatch<'_, W, M, T> {
    fn trace<O: Observer>(&self, rays: &[Ray], hits: &mut [Hit], obs: &mut O) {
        batch::<W, M, T, O>(self.mem, self.root, rays, hits, self.query, obs);
    }
}

/// The packet loop: the AVX2 one where the processor has AVX2, else the reference packet kernel
/// with the baseline fast child kernel.
#[inline(always)]
fn packets<const W: usize, M: WideMemory<W>, T: TriangleTest, O: Observer + Default>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    done: impl FnMut(usize, O),
) {
    #[cfg(target_arch = "x86_64")]
    if crate::x86::available() {
        // SAFETY: the processor has AVX2 (checked just above).
        unsafe { crate::x86::packet::trace_batch::<W, M, T, O>(mem, root, rays, hits, query, done) };
        return;
    }
    trace_wide_packets::<W, M, T, FastKernel, ReferencePacketKernel, O>(mem, root, rays, hits, query, done);
}

/// The stream loop: the AVX2 one where the processor has AVX2, else the baseline fast kernel.
/// The chunk must start a stream ([`STREAM_RAYS`](raytrail_core::wide::STREAM_RAYS)).
#[inline(always)]
fn streams<const W: usize, M: WideMemory<W>, T: TriangleTest, O: Observer + Default>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    done: impl FnMut(usize, O),
) {
    #[cfg(target_arch = "x86_64")]
    if crate::x86::available() {
        // SAFETY: the processor has AVX2 (checked just above).
        unsafe { crate::x86::stream::trace_streams::<W, M, T, O>(mem, root, rays, hits, query, done) };
        return;
    }
    trace_wide_streams::<W, M, T, FastKernel, O>(mem, root, rays, hits, query, done);
}

/// The batch loop: the AVX2 one where the processor has AVX2, else the baseline fast kernel (SSE
/// on x86_64). Every recording mode goes through here, so the conformance suite checks the path
/// the timings take.
#[inline(always)]
fn batch<const W: usize, M: WideMemory<W>, T: TriangleTest, O: Observer>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    obs: &mut O,
) {
    #[cfg(target_arch = "x86_64")]
    if crate::x86::available() {
        // SAFETY: the processor has AVX2 (checked just above).
        unsafe { crate::x86::single_ray::trace_batch::<W, M, T, O>(mem, root, rays, hits, query, obs) };
        return;
    }
    trace_wide_batch::<W, M, T, FastKernel, O>(mem, root, rays, hits, query, obs);
}
