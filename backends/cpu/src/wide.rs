//! The wide-BVH methods' loop for one chunk, monomorphized per width x memory x triangle test x
//! recording, with the fast child kernel (SIMD box tests, the sorting network), in the AVX2 loop
//! where the processor has AVX2; the packet method's loop over the chunk's packets and the stream
//! method's over its streams likewise. The memory prefetches hit children where that pays (a large
//! tree, incoherent rays, any-hit ones only in packets and streams: [`worth_prefetching`]; in the
//! packet loop, only the subtrees handed over to single rays prefetch).

use crate::chunk::Chunk;
use core::marker::PhantomData;
use raytrail_core::intersect::{MollerTrumbore, TriangleTest, Watertight};
use raytrail_core::method::Query;
use raytrail_core::method::{Method, WideMethod};
use raytrail_core::observe::{Both, Counters, NoObserver, Observer, Recorder};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Record, TraceOptions, TriangleTestKind};
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
    if method.keyed() {
        return crate::keyed::trace_chunk(scene, method, opts, chunk);
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
        if worth_prefetching(bytes, chunk.rays, self.opts.query, self.method.shares_walks()) {
            self.test(&PrefetchingMemory(mem), chunk)
        } else {
            self.test(&mem, chunk)
        }
    }

    fn test<const W: usize, M: WideMemory<W>>(&self, mem: &M, chunk: Chunk<'_>) -> Result<Counters, Error> {
        match self.opts.triangle_test {
            TriangleTestKind::Watertight => self.run::<W, M, Watertight>(mem, chunk),
            TriangleTestKind::MollerTrumbore => self.run::<W, M, MollerTrumbore>(mem, chunk),
        }
    }

    fn run<const W: usize, M: WideMemory<W>, T: TriangleTest>(
        &self,
        mem: &M,
        chunk: Chunk<'_>,
    ) -> Result<Counters, Error> {
        let (root, query) = (self.root, self.opts.query);
        if self.method.shares_walks() {
            let streams = self.method.streams();
            return self.run_shared(chunk, &SharedWalk::<W, M, T> { mem, root, query, streams, test: PhantomData });
        }
        let stack = StackBatch::<W, M, T> { mem, root, query, test: PhantomData };
        record_rays(self.scene, self.method, self.opts.record, chunk, &stack)
    }

    /// [`WideRun::run`] for a method whose rays share walks of the tree (packets, streams): each
    /// ray's observer comes back from the walk.
    fn run_shared(&self, chunk: Chunk<'_>, walks: &impl SharedWalks) -> Result<Counters, Error> {
        let mut counters = Counters::default();
        match self.opts.record {
            Record::Nothing => walks.trace::<NoObserver>(chunk.rays, chunk.hits, &mut |_, _| {}),
            Record::Counters => walks.trace::<Counters>(chunk.rays, chunk.hits, &mut |_, c| counters.add(&c)),
            Record::Enumerations => {
                let mut failed = None;
                let slots = &mut *chunk.enumerations;
                walks.trace::<Both<Counters, Recorder>>(chunk.rays, chunk.hits, &mut |i, o| {
                    counters.add(&o.0);
                    match self.scene.canonical_ids(Method::Wide(self.method), o.1.nodes.iter().copied()) {
                        Ok(ids) => slots[i] = ids,
                        Err(e) => failed = Some(e),
                    }
                });
                if let Some(e) = failed {
                    return Err(e);
                }
            }
        }
        counters.rays = chunk.rays.len() as u64;
        Ok(counters)
    }
}

/// A loop over a chunk whose rays share walks of the tree, generic over what observes each ray.
trait SharedWalks {
    /// Traces `rays` into `hits`, handing each ray's index and observer to `done`.
    fn trace<O: Observer + Default>(&self, rays: &[Ray], hits: &mut [Hit], done: &mut impl FnMut(usize, O));
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

/// One loop over a slice of rays, generic over what observes it (so one recording routine serves
/// the stack and the keyed traversals).
pub(crate) trait RayLoop {
    /// Traces `rays` into `hits`, reporting to `obs`.
    fn trace<O: Observer>(&self, rays: &[Ray], hits: &mut [Hit], obs: &mut O);
}

/// Traces a chunk ray by ray with `rays`, observing what `record` asks for: nothing, counters,
/// or each ray's enumeration in canonical node ids.
pub(crate) fn record_rays(
    scene: &PreparedScene,
    method: WideMethod,
    record: Record,
    chunk: Chunk<'_>,
    rays: &impl RayLoop,
) -> Result<Counters, Error> {
    let mut counters = Counters::default();
    match record {
        Record::Nothing => rays.trace(chunk.rays, chunk.hits, &mut NoObserver),
        Record::Counters => rays.trace(chunk.rays, chunk.hits, &mut counters),
        Record::Enumerations => {
            let slots = chunk.rays.iter().zip(chunk.hits.iter_mut()).zip(chunk.enumerations.iter_mut());
            for ((ray, hit), nodes) in slots {
                let mut obs = Both(counters, Recorder::default());
                rays.trace(core::slice::from_ref(ray), core::slice::from_mut(hit), &mut obs);
                counters = obs.0;
                *nodes = scene.canonical_ids(Method::Wide(method), obs.1.nodes.iter().copied())?;
            }
        }
    }
    counters.rays = chunk.rays.len() as u64;
    Ok(counters)
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
    if crate::avx::available() {
        // SAFETY: the processor has AVX2 (checked just above).
        unsafe { crate::avx_packet::trace_batch::<W, M, T, O>(mem, root, rays, hits, query, done) };
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
    if crate::avx::available() {
        // SAFETY: the processor has AVX2 (checked just above).
        unsafe { crate::avx::trace_streams::<W, M, T, O>(mem, root, rays, hits, query, done) };
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
    if crate::avx::available() {
        // SAFETY: the processor has AVX2 (checked just above).
        unsafe { crate::avx::trace_batch::<W, M, T, O>(mem, root, rays, hits, query, obs) };
        return;
    }
    trace_wide_batch::<W, M, T, FastKernel, O>(mem, root, rays, hits, query, obs);
}
