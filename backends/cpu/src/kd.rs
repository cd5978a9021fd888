//! The kd-tree methods' loop for one chunk: single rays, or packets grouped as the core says
//! ([`raytrail_core::traverse::packets`]).

use crate::chunk::Chunk;
use crate::record::{record, with_test, Independent, RayLoop, Shared, SharedWalks, WithTest};
use core::marker::PhantomData;
use raytrail_core::intersect::TriangleTest;
use raytrail_core::kd::traverse::{trace_kd_packet, trace_kd_ray, KdRoot, RestartPolicy, PACKET_WIDTH};
use raytrail_core::kd::KdSliceMemory;
use raytrail_core::method::{KdMethod, Method, Query};
use raytrail_core::observe::{Counters, Observer};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::TraceOptions;
use raytrail_core::traverse::packets::{packet_slots, PADDING};
use raytrail_core::{Error, Hit, Ray};

/// Traces one chunk with `method`; returns its counters. The chunk must not split the packet
/// grouping's spans ([`GROUPING_RAYS`](raytrail_core::traverse::packets::GROUPING_RAYS)).
pub(crate) fn trace_chunk(
    scene: &PreparedScene,
    method: KdMethod,
    opts: &TraceOptions,
    chunk: Chunk<'_>,
) -> Result<Counters, Error> {
    let run = KdRun { scene, method, opts, mem: scene.kd_memory()?, root: scene.kd_root()?, chunk };
    with_test(opts.triangle_test, run)
}

/// What a chunk is traced with.
struct KdRun<'a, 'c> {
    scene: &'a PreparedScene,
    method: KdMethod,
    opts: &'a TraceOptions,
    mem: KdSliceMemory<'a>,
    root: KdRoot,
    chunk: Chunk<'c>,
}

impl WithTest for KdRun<'_, '_> {
    type Output = Result<Counters, Error>;
    fn with<T: TriangleTest>(self) -> Self::Output {
        let KdRun { scene, method, opts, mem, root, chunk } = self;
        let walk = KdWalk::<T> { method, mem, root, query: opts.query, test: PhantomData };
        let method_id = Method::Kd(method);
        if method == KdMethod::Packet {
            record(scene, method_id, opts.record, chunk, &Shared(&walk))
        } else {
            record(scene, method_id, opts.record, chunk, &Independent(&walk))
        }
    }
}

/// The kd loops over a slice of rays: one ray at a time, or (for the packet method) packets.
struct KdWalk<'a, T> {
    method: KdMethod,
    mem: KdSliceMemory<'a>,
    root: KdRoot,
    query: Query,
    test: PhantomData<T>,
}

impl<T: TriangleTest> RayLoop for KdWalk<'_, T> {
    fn trace<O: Observer>(&self, rays: &[Ray], hits: &mut [Hit], obs: &mut O) {
        // One loop per method, the method a constant in each: the per-ray match leaves the loop,
        // and each walk's registers are its own.
        match self.method {
            KdMethod::Stack => self.each(KdMethod::Stack, rays, hits, obs),
            KdMethod::Restart => self.each(KdMethod::Restart, rays, hits, obs),
            KdMethod::PushDown => self.each(KdMethod::PushDown, rays, hits, obs),
            KdMethod::ShortStack => self.each(KdMethod::ShortStack, rays, hits, obs),
            KdMethod::Packet => self.each(KdMethod::Packet, rays, hits, obs),
        }
    }
}

impl<T: TriangleTest> KdWalk<'_, T> {
    /// Traces each ray alone with `method`.
    #[inline(always)]
    fn each<O: Observer>(&self, method: KdMethod, rays: &[Ray], hits: &mut [Hit], obs: &mut O) {
        for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
            *hit = trace_kd_ray::<_, T, _>(method, &self.mem, &self.root, ray, self.query, obs);
        }
    }
}

impl<T: TriangleTest> SharedWalks for KdWalk<'_, T> {
    fn trace<O: Observer + Default>(&self, rays: &[Ray], hits: &mut [Hit], done: &mut impl FnMut(usize, O)) {
        let policy = RestartPolicy::short_stack(self.root.short_stack);
        // The slots are read in place: a list per packet cost a fifth of a fast ray's time.
        for slots in packet_slots(rays).chunks(PACKET_WIDTH) {
            let n = slots.iter().take_while(|&&i| i != PADDING).count();
            let packet: [Ray; PACKET_WIDTH] = core::array::from_fn(|k| rays[slots[k.min(n - 1)] as usize]);
            let mut out = [Hit::MISS; PACKET_WIDTH];
            let mut obs: [O; PACKET_WIDTH] = Default::default();
            trace_kd_packet::<PACKET_WIDTH, _, T, O>(
                &self.mem,
                &self.root,
                &packet[..n],
                self.query,
                policy,
                &mut out,
                &mut obs,
            );
            for (k, o) in obs.into_iter().enumerate().take(n) {
                hits[slots[k] as usize] = out[k];
                done(slots[k] as usize, o);
            }
        }
    }
}
