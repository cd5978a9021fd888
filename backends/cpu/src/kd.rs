//! The kd-tree methods' loop for one chunk: single rays, or packets grouped as the core says
//! ([`raytrail_core::kd::traverse::packets`]).

use crate::chunk::Chunk;
use raytrail_core::intersect::{MollerTrumbore, TriangleTest, Watertight};
use raytrail_core::kd::traverse::packets::{packet_slots, PADDING};
use raytrail_core::kd::traverse::{trace_kd_packet, trace_kd_ray, KdRoot, RestartPolicy, PACKET_WIDTH};
use raytrail_core::kd::KdSliceMemory;
use raytrail_core::method::{KdMethod, Method};
use raytrail_core::observe::{Both, Counters, NoObserver, Observer, Recorder};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Record, TraceOptions, TriangleTestKind};
use raytrail_core::{Error, Hit, Ray};

/// Traces one chunk with `method`; returns its counters. The chunk must not split the packet
/// grouping's chunks ([`PACKET_CHUNK`](raytrail_core::kd::traverse::packets::PACKET_CHUNK)).
pub(crate) fn trace_chunk(
    scene: &PreparedScene,
    method: KdMethod,
    opts: &TraceOptions,
    chunk: Chunk<'_>,
) -> Result<Counters, Error> {
    let run = KdRun { scene, method, opts, mem: scene.kd_memory()?, root: scene.kd_root()? };
    match opts.triangle_test {
        TriangleTestKind::Watertight => run.go::<Watertight>(chunk),
        TriangleTestKind::MollerTrumbore => run.go::<MollerTrumbore>(chunk),
    }
}

struct KdRun<'a> {
    scene: &'a PreparedScene,
    method: KdMethod,
    opts: &'a TraceOptions,
    mem: KdSliceMemory<'a>,
    root: KdRoot,
}

impl KdRun<'_> {
    fn go<T: TriangleTest>(&self, chunk: Chunk<'_>) -> Result<Counters, Error> {
        let mut counters = match self.opts.record {
            Record::Nothing => {
                self.each::<T, NoObserver>(chunk.rays, chunk.hits, |_, _| Ok(()))?;
                Counters::default()
            }
            Record::Counters => {
                let mut total = Counters::default();
                self.each::<T, Counters>(chunk.rays, chunk.hits, |_, c| {
                    total.add(&c);
                    Ok(())
                })?;
                total
            }
            Record::Enumerations => {
                let mut total = Counters::default();
                let slots = &mut *chunk.enumerations;
                self.each::<T, Both<Counters, Recorder>>(chunk.rays, chunk.hits, |i, o| {
                    total.add(&o.0);
                    slots[i] = self.scene.canonical_ids(Method::Kd(self.method), o.1.nodes.iter().copied())?;
                    Ok(())
                })?;
                total
            }
        };
        counters.rays = chunk.rays.len() as u64;
        Ok(counters)
    }

    /// Traces every ray of the chunk with a fresh observer, handing each ray's observer to `done`.
    fn each<T: TriangleTest, O: Observer + Default>(
        &self,
        rays: &[Ray],
        hits: &mut [Hit],
        mut done: impl FnMut(usize, O) -> Result<(), Error>,
    ) -> Result<(), Error> {
        let query = self.opts.query;
        if self.method != KdMethod::Packet {
            for (i, (ray, hit)) in rays.iter().zip(hits.iter_mut()).enumerate() {
                let mut o = O::default();
                *hit = trace_kd_ray::<_, T, _>(self.method, &self.mem, &self.root, ray, query, &mut o);
                done(i, o)?;
            }
            return Ok(());
        }
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
                query,
                policy,
                &mut out,
                &mut obs,
            );
            for (k, o) in obs.into_iter().enumerate().take(n) {
                hits[slots[k] as usize] = out[k];
                done(slots[k] as usize, o)?;
            }
        }
        Ok(())
    }
}
