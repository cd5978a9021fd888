//! The kd-tree methods' loops: single rays, or packets of one direction octant.

use crate::dispatch::Chunk;
use raytrail_core::bvh2::NodeRef;
use raytrail_core::intersect::{MollerTrumbore, TriangleTest, Watertight};
use raytrail_core::kd::traverse::{trace_kd_packet, trace_kd_ray, KdRoot, PACKET_WIDTH};
use raytrail_core::kd::KdSliceMemory;
use raytrail_core::observe::{Both, Counters, NoObserver, Observer, Recorder};
use raytrail_core::prepared::PreparedBvh2;
use raytrail_core::trace::{Record, TraceOptions, TriangleTestKind};
use raytrail_core::traverse::{Method, Query};
use raytrail_core::{Error, Hit, Ray};

/// Traces one chunk with a kd method; returns its counters.
pub(crate) fn trace_kd_chunk(scene: &PreparedBvh2, opts: &TraceOptions, chunk: Chunk<'_>) -> Result<Counters, Error> {
    let run = KdRun { opts, mem: scene.kd_memory()?, root: scene.kd_root()? };
    Ok(match opts.triangle_test {
        TriangleTestKind::Watertight => run.go::<Watertight>(chunk),
        TriangleTestKind::MollerTrumbore => run.go::<MollerTrumbore>(chunk),
    })
}

/// The leaves of a kd enumeration (restart methods revisit inner nodes; leaves are what the
/// conformance suite compares).
fn leaves(nodes: &[NodeRef]) -> Vec<u32> {
    nodes.iter().filter(|r| r.is_leaf()).map(|r| r.offset()).collect()
}

struct KdRun<'a> {
    opts: &'a TraceOptions,
    mem: KdSliceMemory<'a>,
    root: KdRoot,
}

impl KdRun<'_> {
    fn go<T: TriangleTest>(&self, chunk: Chunk<'_>) -> Counters {
        let mut counters = match self.opts.record {
            Record::Nothing => {
                self.each::<T, NoObserver>(chunk.rays, chunk.hits, |_, _| {});
                Counters::default()
            }
            Record::Counters => {
                let mut total = Counters::default();
                self.each::<T, Counters>(chunk.rays, chunk.hits, |_, c| total.add(&c));
                total
            }
            Record::Enumerations => {
                let mut total = Counters::default();
                let slots = &mut *chunk.enumerations;
                self.each::<T, Both<Counters, Recorder>>(chunk.rays, chunk.hits, |i, o| {
                    total.add(&o.0);
                    slots[i] = leaves(&o.1.nodes);
                });
                total
            }
        };
        counters.rays = chunk.rays.len() as u64;
        counters
    }

    /// Traces every ray of the chunk with a fresh observer, handing each ray's observer to `done`.
    fn each<T: TriangleTest, O: Observer + Default>(
        &self,
        rays: &[Ray],
        hits: &mut [Hit],
        mut done: impl FnMut(usize, O),
    ) {
        let any = self.opts.query == Query::Any;
        if self.opts.method != Method::KdPacket {
            for (i, (ray, hit)) in rays.iter().zip(hits.iter_mut()).enumerate() {
                let mut o = O::default();
                *hit = trace_kd_ray::<_, T, _>(self.opts.method, &self.mem, &self.root, ray, self.opts.query, &mut o);
                done(i, o);
            }
            return;
        }
        // Packets share each node's child order, so they hold rays of one direction octant.
        let octant = |r: &Ray| {
            (r.dir[0].is_sign_negative() as u8)
                | (r.dir[1].is_sign_negative() as u8) << 1
                | (r.dir[2].is_sign_negative() as u8) << 2
        };
        let mut order: Vec<u32> = (0..rays.len() as u32).collect();
        order.sort_by_key(|&i| octant(&rays[i as usize]));
        let mut start = 0;
        while start < order.len() {
            let oct = octant(&rays[order[start] as usize]);
            let mut end = start + 1;
            while end < order.len() && end - start < PACKET_WIDTH && octant(&rays[order[end] as usize]) == oct {
                end += 1;
            }
            let idx = &order[start..end];
            let packet: Vec<Ray> = idx.iter().map(|&i| rays[i as usize]).collect();
            let mut out = [Hit::MISS; PACKET_WIDTH];
            let mut obs: [O; PACKET_WIDTH] = Default::default();
            trace_kd_packet::<PACKET_WIDTH, _, T, O>(
                &self.mem,
                &self.root,
                &packet,
                any,
                self.root.short_stack,
                true,
                &mut out,
                &mut obs,
            );
            for (k, o) in obs.into_iter().enumerate().take(idx.len()) {
                hits[idx[k] as usize] = out[k];
                done(idx[k] as usize, o);
            }
            start = end;
        }
    }
}
