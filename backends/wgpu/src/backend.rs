//! The wgpu backend: the [`Trace`] implementation.

use crate::batch::{self, SceneBindings};
use crate::compose::Variant;
use crate::device::{device_error, Gpu, KernelForm};
use crate::params::Params;
use crate::pipelines::Pipelines;
use crate::record;
use crate::scene::WgpuScene;
use crate::stream::kernels::StreamKernels;
use raytrail_core::bvh2::NodeRef;
use raytrail_core::kd::traverse::packets::{packet_slots, PADDING};
use raytrail_core::kd::traverse::PACKET_WIDTH;
use raytrail_core::method::{KdMethod, Method};
use raytrail_core::observe::Counters;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::stream::{StreamParams, StreamPlan};
use raytrail_core::trace::{check_buffers, Record, Report, Trace, TraceOptions};
use raytrail_core::wide::WideChild;
use raytrail_core::{Error, Hit, Ray};
use std::sync::Arc;
use std::time::Instant;

/// Node events a ray may record before its slot overflows; rays that overflow are traced again
/// with room for all of their events, so nothing is lost.
const DEFAULT_RECORD_CAP: usize = 256;

/// The most node events a ray may record: far beyond any intact tree's enumeration.
const MAX_RECORD_CAP: usize = 1 << 24;

/// Bytes of per-batch buffers (rays, hits, records) the backend aims to stay under.
const BATCH_BYTES: usize = 256 << 20;

/// Rays per packet of the kd-packet kernel: the core's packet width.
const PACKET: usize = PACKET_WIDTH;

/// The wgpu backend: one device, kernels compiled on first use.
pub struct WgpuBackend {
    gpu: Gpu,
    pipelines: Pipelines,
    /// The stream method's kernels, or why the adapter cannot run them.
    stream: Result<StreamKernels, String>,
}

impl WgpuBackend {
    /// Opens the first adapter wgpu finds, with the kernel form [`KERNEL_FORM`](crate::KERNEL_FORM)
    /// names (default: auto); fails with [`Error::Device`] naming why there is none.
    pub fn new() -> Result<WgpuBackend, Error> {
        Self::with_kernel_form(KernelForm::from_env()?)
    }

    /// Opens the first adapter wgpu finds, handing it kernels in `form`.
    pub fn with_kernel_form(form: KernelForm) -> Result<WgpuBackend, Error> {
        let gpu = Gpu::open(form)?;
        let pipelines = Pipelines::new(&gpu);
        let stream = StreamKernels::new(&gpu).map_err(|e| e.to_string());
        Ok(WgpuBackend { gpu, pipelines, stream })
    }

    /// The adapter, for reports.
    pub fn adapter(&self) -> String {
        self.gpu.describe()
    }

    /// Whether [`Report::seconds`] are GPU time from timestamp queries (otherwise wall-clock time
    /// of the whole call, transfers included).
    pub fn has_gpu_timer(&self) -> bool {
        self.gpu.timestamps
    }

    /// Measures what the adapter's compiler does to float arithmetic over `samples` samples, and
    /// whether the kernels' fenced products and correctly rounded division match the CPU.
    pub fn probe_numerics(&self, samples: usize) -> Result<crate::NumericsProbe, Error> {
        crate::probe::probe(&self.gpu, samples)
    }

    /// Compiles the kernels a trace of `method` with `options` runs (for the stream method, all of
    /// its stages), so that a first timed call does not pay for compilation.
    pub fn warm_up(&self, scene: &WgpuScene, method: Method, options: &TraceOptions) -> Result<(), Error> {
        if let Method::Stream(m) = method {
            return self.stream_kernels()?.warm_up(&self.gpu, m, options);
        }
        self.pipelines.get(&self.gpu, &variant(scene, method, options)).map(|_| ())
    }

    /// The stream method's kernels, or [`Error::Device`] naming why the adapter cannot run them.
    fn stream_kernels(&self) -> Result<&StreamKernels, Error> {
        self.stream.as_ref().map_err(|why| device_error(format!("the stream method is unavailable: {why}")))
    }

    /// The stream method's stages one to three on the device (keys, sorted order, packet bounds,
    /// frustums, the traversal's final queue, ranges and figures), read back in the core's form:
    /// `raytrail_core::stream::pipeline::plan` gives the same arrays, bit for bit.
    pub fn stream_plan(&self, scene: &WgpuScene, rays: &[Ray], params: &StreamParams) -> Result<StreamPlan, Error> {
        crate::stream::plan_only(&self.gpu, self.stream_kernels()?, scene, rays, params)
    }

    /// Rays per batch: within the adapter's binding and dispatch limits and the byte budget.
    fn batch_rays(&self, record_stride: usize) -> usize {
        let l = &self.gpu.limits;
        let per_ray = 32 + 16 + 4 * record_stride;
        let binding = l.max_storage_buffer_binding_size as usize;
        let by_binding = (binding / 32).min(binding / (4 * record_stride.max(1)));
        let by_dispatch = l.max_compute_workgroups_per_dimension as usize * 64 * 1024;
        let n = (BATCH_BYTES / per_ray).min(by_binding).min(by_dispatch).max(PACKET);
        n - n % PACKET
    }

    /// Traces `rays` with a record capacity of `cap` node events per ray.
    fn trace_with_cap(
        &self,
        scene: &WgpuScene,
        rays: &[Ray],
        options: &TraceOptions,
        cap: usize,
    ) -> Result<Traced, Error> {
        let p = &scene.prepared;
        let v = variant(scene, options.method, options);
        let pipeline = self.pipelines.get(&self.gpu, &v)?;
        let stride = match options.record {
            Record::Nothing => 0,
            Record::Counters => record::stride(0),
            Record::Enumerations => record::stride(cap),
        };
        let mut params = Params { record_stride: stride as u32, record_cap: cap as u32, ..Params::default() };
        let bindings = match options.method {
            Method::Bvh2(m) => {
                let root = p.root(m)?;
                let layout =
                    scene.layout_for(m).ok_or(Error::NotPrepared { method: m.name(), missing: "its BVH2 layout" })?;
                params.root = root.node.0;
                params.max_steps = root.max_steps;
                params.scene_scale = root.scene_scale;
                params.leaf_base = layout.leaf_base;
                let hash = match scene.hash_for(m) {
                    Some(h) => {
                        params.d_mask = h.d_mask;
                        params.h = h.h;
                        &h.buffer
                    }
                    None if m.needs_hash() => {
                        return Err(Error::NotPrepared { method: m.name(), missing: "the hash tables" })
                    }
                    None => &scene.empty,
                };
                SceneBindings { bvh: &layout.buffer, hash, kd: &scene.empty }
            }
            Method::Kd(_) => {
                let root = p.kd_root()?;
                let kd = scene.kd.as_ref().ok_or(Error::NotPrepared { method: "kd", missing: "the kd-tree" })?;
                params.max_steps = root.max_steps;
                params.scene_scale = root.scene_scale;
                params.short_stack = root.short_stack as u32;
                params.kd_prims = kd.prims;
                params.kd_tris = kd.tris;
                params.kd_lo = [root.lo.x, root.lo.y, root.lo.z, 0.0];
                params.kd_hi = [root.hi.x, root.hi.y, root.hi.z, 0.0];
                SceneBindings { bvh: &scene.empty, hash: &scene.empty, kd: &kd.buffer }
            }
            Method::Wide(m) => {
                let root = p.wide_root(m)?;
                let tree =
                    scene.wide_for(m).ok_or(Error::NotPrepared { method: m.name(), missing: "its wide tree" })?;
                params.max_steps = root.max_steps;
                params.scene_scale = root.scene_scale;
                params.kd_prims = tree.prims;
                params.kd_tris = tree.tris;
                (params.root, params.wide_root_count) = match root.root {
                    WideChild::Node(n) => (n, 0),
                    WideChild::Leaf { first, count } => (NodeRef::leaf(first).0, count),
                };
                SceneBindings { bvh: &scene.empty, hash: &scene.empty, kd: &tree.buffer }
            }
            other => return Err(Error::Unsupported { method: other.name(), by: "the wgpu backend" }),
        };
        // Packets are grouped as the core says (every backend alike): the batch is rearranged into
        // the grouping's slots, padding as untraceable rays, so that packet `p` is slots
        // `PACKET * p ..`, then put back.
        let order = (options.method == Method::Kd(KdMethod::Packet)).then(|| packet_slots(rays));
        let arranged: Vec<Ray>;
        let work: &[Ray] = match &order {
            Some(o) => {
                let pad = Ray { origin: [f32::NAN; 3], tmin: 0.0, dir: [f32::NAN; 3], tmax: 0.0 };
                arranged = o.iter().map(|&i| if i == PADDING { pad } else { rays[i as usize] }).collect();
                &arranged
            }
            None => rays,
        };
        let per_batch = self.batch_rays(stride);
        let mut hits = Vec::with_capacity(work.len());
        let mut records = Vec::with_capacity(work.len() * stride);
        let mut gpu_seconds = Some(0.0);
        for chunk in work.chunks(per_batch) {
            let invocations = if order.is_some() { chunk.len().div_ceil(PACKET) } else { chunk.len() };
            let out =
                batch::run(&self.gpu, &pipeline, &self.pipelines.bind_layout, &bindings, params, chunk, invocations)?;
            hits.extend(out.hits);
            records.extend(out.records);
            gpu_seconds = gpu_seconds.zip(out.gpu_seconds).map(|(a, b)| a + b);
        }
        if let Some(o) = &order {
            let mut h = vec![Hit::MISS; rays.len()];
            let mut r = vec![0u32; rays.len() * stride];
            for (slot, &i) in o.iter().enumerate() {
                if i != PADDING {
                    h[i as usize] = hits[slot];
                    let (dst, src) = (i as usize * stride, slot * stride);
                    r[dst..dst + stride].copy_from_slice(&records[src..src + stride]);
                }
            }
            return Ok(Traced { hits: h, records: r, stride, gpu_seconds });
        }
        Ok(Traced { hits, records, stride, gpu_seconds })
    }
}

/// What [`WgpuBackend::trace_with_cap`] returns, in the caller's ray order.
struct Traced {
    hits: Vec<Hit>,
    /// `stride` words per ray.
    records: Vec<u32>,
    stride: usize,
    /// GPU seconds, when every batch was timed by timestamp queries.
    gpu_seconds: Option<f64>,
}

/// The kernel variant for `method` on `scene` with `options`.
fn variant(scene: &WgpuScene, method: Method, options: &TraceOptions) -> Variant {
    Variant {
        method,
        keys: scene.prepared.key_width(),
        triangle: options.triangle_test,
        query: options.query,
        record: options.record,
    }
}

/// Canonical ids of one ray's recorded references, by the core's convention.
fn enumeration(p: &PreparedScene, method: Method, refs: &[u32]) -> Result<Vec<u32>, Error> {
    p.canonical_ids(method, refs.iter().map(|&r| NodeRef(r)))
}

impl Trace for WgpuBackend {
    type Prepared = WgpuScene;

    fn name(&self) -> &str {
        "wgpu"
    }

    /// Every BVH2, kd, wide-BVH and stream method (the stream method where the adapter allows its
    /// kernels' bindings).
    fn supports(&self, method: Method) -> bool {
        match method {
            Method::Bvh2(_) | Method::Kd(_) | Method::Wide(_) => true,
            Method::Stream(_) => self.stream.is_ok(),
            _ => false,
        }
    }

    fn prepare(&self, scene: Arc<PreparedScene>) -> Result<WgpuScene, Error> {
        WgpuScene::upload(&self.gpu, scene)
    }

    fn trace(
        &self,
        scene: &WgpuScene,
        rays: &[Ray],
        options: &TraceOptions,
        hits: &mut [Hit],
    ) -> Result<Report, Error> {
        raytrail_core::trace::trace_framed(&scene.prepared, rays, hits, |rays, hits| {
            self.trace_in_frame(scene, rays, options, hits)
        })
    }
}

impl WgpuBackend {
    /// [`Trace::trace`] on rays already in the scene's frame.
    fn trace_in_frame(
        &self,
        scene: &WgpuScene,
        rays: &[Ray],
        options: &TraceOptions,
        hits: &mut [Hit],
    ) -> Result<Report, Error> {
        check_buffers(rays, hits)?;
        if !self.supports(options.method) {
            return Err(Error::Unsupported { method: options.method.name(), by: "the wgpu backend" });
        }
        if let Method::Stream(m) = options.method {
            // The batch as a whole: packets are made from all of its rays.
            scene.prepared.check_prepared(options.method)?;
            return crate::stream::trace(&self.gpu, self.stream_kernels()?, scene, m, rays, options, hits);
        }
        let start = Instant::now();
        let Traced { hits: out, records, stride, gpu_seconds } =
            self.trace_with_cap(scene, rays, options, DEFAULT_RECORD_CAP)?;
        let wall = start.elapsed().as_secs_f64();
        hits.copy_from_slice(&out);
        let mut report = Report::new(rays.len(), gpu_seconds.unwrap_or(wall));
        if options.record == Record::Nothing {
            return Ok(report);
        }
        let mut counters = Counters { rays: rays.len() as u64, ..Counters::default() };
        for slot in records.chunks(stride) {
            record::add_counters(&mut counters, slot);
        }
        report.counters = Some(counters);
        if options.record == Record::Enumerations {
            let mut enumerations = vec![Vec::new(); rays.len()];
            let mut overflowed = Vec::new();
            for (i, slot) in records.chunks(stride).enumerate() {
                match record::node_refs(slot, DEFAULT_RECORD_CAP) {
                    Some(refs) => enumerations[i] = enumeration(&scene.prepared, options.method, refs)?,
                    None => overflowed.push(i),
                }
            }
            // Rays whose events overflowed are traced again with room for the longest of them
            // (twice that: a packet ray's inner-node events depend on its packet mates).
            let mut cap = DEFAULT_RECORD_CAP;
            let mut counts: Vec<usize> = overflowed.iter().map(|&i| records[i * stride] as usize).collect();
            while !overflowed.is_empty() {
                cap = counts.iter().copied().max().unwrap_or(0).max(cap) * 2;
                let again: Vec<Ray> = overflowed.iter().map(|&i| rays[i]).collect();
                let Traced { hits: h2, records: r2, stride: s2, .. } =
                    self.trace_with_cap(scene, &again, options, cap)?;
                let (mut still, mut still_counts) = (Vec::new(), Vec::new());
                for (k, &i) in overflowed.iter().enumerate() {
                    if !h2[k].same_as(&hits[i]) {
                        return Err(device_error(format!("ray {i} found a different hit when traced again")));
                    }
                    let slot = &r2[k * s2..(k + 1) * s2];
                    match record::node_refs(slot, cap) {
                        Some(refs) => enumerations[i] = enumeration(&scene.prepared, options.method, refs)?,
                        None => {
                            still.push(i);
                            still_counts.push(slot[0] as usize);
                        }
                    }
                }
                if !still.is_empty() && cap > MAX_RECORD_CAP {
                    return Err(device_error(format!(
                        "ray {} records more than {MAX_RECORD_CAP} node events",
                        still[0]
                    )));
                }
                (overflowed, counts) = (still, still_counts);
            }
            report.enumerations = Some(enumerations);
        }
        Ok(report)
    }
}
