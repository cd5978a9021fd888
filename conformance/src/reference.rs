//! The serial reference backend: every ray on the calling thread, through the core's per-ray
//! entry points and nothing else. It is the suite's yardstick for other backends (each is compared
//! with it ray by ray), and the smallest example of a backend.

use raytrail_core::all_hits::{AllHits, AllHitsOptions};
use raytrail_core::bvh2::traverse::trace_ray;
use raytrail_core::intersect::{MollerTrumbore, TriangleTest, Watertight};
use raytrail_core::kd::traverse::packets::packets;
use raytrail_core::kd::traverse::{trace_kd_packet, trace_kd_ray, RestartPolicy, PACKET_WIDTH};
use raytrail_core::key::{Key, KeyWidth};
use raytrail_core::method::WideWalk;
use raytrail_core::method::{KdMethod, Method, Query, StreamMethod, WideMethod};
use raytrail_core::nearest::NearestPoint;
use raytrail_core::observe::{Both, Counters, Recorder};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::stream::{trace_stream_with, FrustumCull, Serial};
use raytrail_core::trace::{check_buffers, Record, Report, Trace, TraceOptions, TriangleTestKind};
use raytrail_core::wide::keyed::WideKeyedMemory;
use raytrail_core::wide::packet::{trace_wide_packets, ReferencePacketKernel};
use raytrail_core::wide::ray_stream::trace_wide_streams;
use raytrail_core::wide::trail::trace_wide_trail_ray;
use raytrail_core::wide::traverse::{trace_wide_ray, WideRoot};
use raytrail_core::wide::{ReferenceKernel, WideSliceMemory, WideTree};
use raytrail_core::{Error, Hit, Ray};
use std::sync::Arc;
use std::time::Instant;

/// Traces one ray at a time with the core's state machines, always observing, and keeps what
/// the options ask for.
#[derive(Clone, Copy, Debug, Default)]
pub struct SerialBackend;

/// What one ray left: its hit and its observer.
type Traced = (Hit, Both<Counters, Recorder>);

impl SerialBackend {
    fn trace_all<T: TriangleTest>(
        scene: &PreparedScene,
        method: Method,
        query: Query,
        rays: &[Ray],
    ) -> Result<Vec<Traced>, Error> {
        let fresh = || Both(Counters::default(), Recorder::default());
        match method {
            Method::Bvh2(m) => {
                let (mem, root) = (scene.memory(m)?, scene.root(m)?);
                Ok(rays
                    .iter()
                    .map(|ray| {
                        let mut o = fresh();
                        let hit = match scene.key_width() {
                            KeyWidth::W32 => trace_ray::<u32, _, T, _>(m, &mem, root, ray, query, &mut o),
                            KeyWidth::W64 => trace_ray::<u64, _, T, _>(m, &mem, root, ray, query, &mut o),
                        };
                        (hit, o)
                    })
                    .collect())
            }
            Method::Kd(KdMethod::Packet) => {
                let (mem, root) = (scene.kd_memory()?, scene.kd_root()?);
                let mut out: Vec<Traced> = (0..rays.len()).map(|_| (Hit::MISS, fresh())).collect();
                let policy = RestartPolicy::short_stack(root.short_stack);
                for idx in packets(rays) {
                    let packet: Vec<Ray> = idx.iter().map(|&i| rays[i as usize]).collect();
                    let mut hits = [Hit::MISS; PACKET_WIDTH];
                    let mut obs: [Both<Counters, Recorder>; PACKET_WIDTH] = Default::default();
                    trace_kd_packet::<PACKET_WIDTH, _, T, _>(&mem, &root, &packet, query, policy, &mut hits, &mut obs);
                    for ((&i, hit), o) in idx.iter().zip(hits).zip(obs) {
                        out[i as usize] = (hit, o);
                    }
                }
                Ok(out)
            }
            Method::Kd(m) => {
                let (mem, root) = (scene.kd_memory()?, scene.kd_root()?);
                Ok(rays
                    .iter()
                    .map(|ray| {
                        let mut o = fresh();
                        (trace_kd_ray::<_, T, _>(m, &mem, &root, ray, query, &mut o), o)
                    })
                    .collect())
            }
            Method::Wide(m) if m.walk() == WideWalk::Trail => {
                let root = scene.wide_root(m)?;
                let (mem, keys) = scene.wide_keyed(m)?;
                Ok(match keys {
                    KeyWidth::W32 => Self::keyed::<u32, _, T>(&mem, root, rays, query),
                    KeyWidth::W64 => Self::keyed::<u64, _, T>(&mem, root, rays, query),
                })
            }
            Method::Wide(m) => {
                let root = scene.wide_root(m)?;
                match scene.wide_tree(m)? {
                    WideTree::Four(t) => Ok(Self::wide::<_, T>(&t.memory(), root, rays, query, m)),
                    WideTree::Eight(t) => Ok(Self::wide::<_, T>(&t.memory(), root, rays, query, m)),
                }
            }
            other => Err(Error::Unsupported { method: other.name(), by: "the serial reference backend" }),
        }
    }
}

impl SerialBackend {
    /// Wide trees with the reference kernel (one child box at a time, an insertion sort): the
    /// scalar traversal every fast path's enumeration must equal. A packet method in the packets
    /// of the grouping, each ray's box tests one child at a time ([`ReferencePacketKernel`]); a
    /// stream method in its streams.
    fn wide<const W: usize, T: TriangleTest>(
        mem: &WideSliceMemory<'_, W>,
        root: WideRoot,
        rays: &[Ray],
        query: Query,
        method: WideMethod,
    ) -> Vec<Traced> {
        if method.walk().shares_walks() {
            let mut hits = vec![Hit::MISS; rays.len()];
            let mut observers = Vec::with_capacity(rays.len());
            let done = |i, o| observers.push((i, o));
            type Obs = Both<Counters, Recorder>;
            if method.walk() == WideWalk::RayLists {
                trace_wide_streams::<W, _, T, ReferenceKernel, Obs>(mem, root, rays, &mut hits, query, done);
            } else {
                trace_wide_packets::<W, _, T, ReferenceKernel, ReferencePacketKernel, Obs>(
                    mem, root, rays, &mut hits, query, done,
                );
            }
            let mut out: Vec<Traced> = (0..rays.len()).map(|_| (Hit::MISS, Default::default())).collect();
            for (i, o) in observers {
                out[i] = (hits[i], o);
            }
            return out;
        }
        rays.iter()
            .map(|ray| {
                let mut o = Both(Counters::default(), Recorder::default());
                (trace_wide_ray::<W, _, T, ReferenceKernel, _>(mem, root, ray, query, &mut o), o)
            })
            .collect()
    }
}

impl SerialBackend {
    /// The stackless trail walk with the reference kernel, one ray at a time.
    fn keyed<K: Key, M: WideKeyedMemory<4>, T: TriangleTest>(
        mem: &M,
        root: WideRoot,
        rays: &[Ray],
        query: Query,
    ) -> Vec<Traced> {
        rays.iter()
            .map(|ray| {
                let mut o = Both(Counters::default(), Recorder::default());
                (trace_wide_trail_ray::<4, K, M, T, ReferenceKernel, _>(mem, root, ray, query, &mut o), o)
            })
            .collect()
    }
}

impl SerialBackend {
    /// The stream pipeline with every stage serial, the reference frustum test and one triangle
    /// at a time, always counting.
    fn stream(
        scene: &PreparedScene,
        method: StreamMethod,
        opts: &TraceOptions,
        rays: &[Ray],
        hits: &mut [Hit],
    ) -> Result<Report, Error> {
        let s = scene.stream_scene(method)?;
        let start = Instant::now();
        let out = trace_stream_with::<_, FrustumCull, ReferenceKernel>(&Serial, &s, rays, hits, opts, true)?;
        let mut report = Report::new(rays.len(), start.elapsed().as_secs_f64());
        report.counters = (opts.record != Record::Nothing).then(|| {
            let mut c = out.counters.unwrap_or_default();
            c.rays = rays.len() as u64;
            c
        });
        report.enumerations = out.enumerations;
        report.stream = Some(out.stats);
        Ok(report)
    }
}

impl Trace for SerialBackend {
    type Prepared = Arc<PreparedScene>;

    fn name(&self) -> &str {
        "serial"
    }

    /// Every BVH2, kd, wide-BVH and stream method.
    fn supports(&self, method: Method) -> bool {
        matches!(method, Method::Bvh2(_) | Method::Kd(_) | Method::Wide(_) | Method::Stream(_))
    }

    fn prepare(&self, scene: Arc<PreparedScene>) -> Result<Arc<PreparedScene>, Error> {
        Ok(scene)
    }

    fn trace(
        &self,
        scene: &Arc<PreparedScene>,
        rays: &[Ray],
        opts: &TraceOptions,
        hits: &mut [Hit],
    ) -> Result<Report, Error> {
        raytrail_core::trace::trace_framed(scene, rays, hits, |rays, hits| self.trace_in_frame(scene, rays, opts, hits))
    }

    /// The core's walk, one ray after another.
    fn all_hits(&self, scene: &Arc<PreparedScene>, rays: &[Ray], options: &AllHitsOptions) -> Result<AllHits, Error> {
        AllHits::trace(scene, rays, options)
    }

    /// The core's walk, one point after another.
    fn nearest_points(
        &self,
        scene: &Arc<PreparedScene>,
        points: &[[f32; 3]],
        radius: f32,
    ) -> Result<Vec<Option<NearestPoint>>, Error> {
        raytrail_core::nearest::nearest_points(scene, points, radius)
    }
}

impl SerialBackend {
    /// [`Trace::trace`] on rays already in the scene's frame.
    fn trace_in_frame(
        &self,
        scene: &Arc<PreparedScene>,
        rays: &[Ray],
        opts: &TraceOptions,
        hits: &mut [Hit],
    ) -> Result<Report, Error> {
        check_buffers(rays, hits)?;
        scene.check_prepared(opts.method)?;
        if let Method::Stream(m) = opts.method {
            return Self::stream(scene, m, opts, rays, hits);
        }
        let start = Instant::now();
        let traced = match opts.triangle_test {
            TriangleTestKind::Watertight => Self::trace_all::<Watertight>(scene, opts.method, opts.query, rays)?,
            TriangleTestKind::MollerTrumbore => {
                Self::trace_all::<MollerTrumbore>(scene, opts.method, opts.query, rays)?
            }
        };
        let mut report = Report::new(rays.len(), start.elapsed().as_secs_f64());
        let mut counters = Counters::default();
        let mut enumerations = Vec::new();
        for ((hit, o), slot) in traced.into_iter().zip(hits.iter_mut()) {
            *slot = hit;
            counters.add(&o.0);
            if opts.record == Record::Enumerations {
                enumerations.push(scene.canonical_ids(opts.method, o.1.nodes)?);
            }
        }
        counters.rays = rays.len() as u64;
        report.counters = (opts.record != Record::Nothing).then_some(counters);
        report.enumerations = (opts.record == Record::Enumerations).then_some(enumerations);
        Ok(report)
    }
}
