//! The wgpu backend: the [`Trace`] implementation.

use crate::batch;
use crate::config::GpuConfig;
use crate::device::{device_error, Gpu, KernelForm};
use crate::launch::{self, Arranged};
use crate::pipelines::Pipelines;
use crate::record;
use crate::scene::WgpuScene;
use crate::stream::kernels::StreamKernels;
use crate::workspace::bytes_moved;
use raytrail_core::all_hits::{AllHits, AllHitsOptions};
use raytrail_core::bvh2::NodeRef;
use raytrail_core::method::Method;
use raytrail_core::nearest::NearestPoint;
use raytrail_core::observe::Counters;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::stream::{StreamParams, StreamPlan};
use raytrail_core::trace::{check_buffers, Record, Report, Trace, TraceOptions};
use raytrail_core::{Error, Hit, Ray};
use std::sync::Arc;
use std::time::Instant;

/// Node events a ray may record before its slot overflows; rays that overflow are traced again
/// with room for all of their events, so nothing is lost.
const DEFAULT_RECORD_CAP: usize = 256;

/// The most node events a ray may record: far beyond any intact tree's enumeration.
const MAX_RECORD_CAP: usize = 1 << 24;

/// The wgpu backend: one device, kernels compiled on first use, and how traces are spread over
/// the device ([`GpuConfig`]). Backends made by [`WgpuBackend::configured`] share the device and
/// the compiled kernels.
pub struct WgpuBackend {
    pub(crate) gpu: Arc<Gpu>,
    pub(crate) pipelines: Arc<Pipelines>,
    /// The stream method's kernels, or why the adapter cannot run them.
    stream: Arc<Result<StreamKernels, String>>,
    pub(crate) config: GpuConfig,
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
        Ok(WgpuBackend {
            gpu: Arc::new(gpu),
            pipelines: Arc::new(pipelines),
            stream: Arc::new(stream),
            config: GpuConfig::default(),
        })
    }

    /// This backend's device and kernels with other settings (batch size, batches in flight,
    /// dispatch, workgroup size); an error names a setting outside the adapter's limits. Scenes
    /// prepared by either backend serve both.
    pub fn configured(&self, config: GpuConfig) -> Result<WgpuBackend, Error> {
        config.check(&self.gpu.limits)?;
        Ok(WgpuBackend {
            gpu: self.gpu.clone(),
            pipelines: self.pipelines.clone(),
            stream: self.stream.clone(),
            config,
        })
    }

    /// The settings traces run with.
    pub fn config(&self) -> &GpuConfig {
        &self.config
    }

    /// The adapter, for reports.
    pub fn adapter(&self) -> String {
        self.gpu.describe()
    }

    /// Whether [`Report::kernel_seconds`] are measured (GPU timestamps around every batch).
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
        let mut options = *options;
        options.method = method;
        self.pipelines.get(&self.gpu, &launch::variant(scene, &options, &self.config)).map(|_| ())
    }

    /// The stream method's kernels, or [`Error::Device`] naming why the adapter cannot run them.
    pub(crate) fn stream_kernels(&self) -> Result<&StreamKernels, Error> {
        self.stream.as_ref().as_ref().map_err(|why| device_error(format!("the stream method is unavailable: {why}")))
    }

    /// The stream method's stages one to three on the device (keys, sorted order, packet bounds,
    /// frustums, the traversal's final queue, ranges and figures), read back in the core's form:
    /// `raytrail_core::stream::pipeline::plan` gives the same arrays, bit for bit.
    pub fn stream_plan(&self, scene: &WgpuScene, rays: &[Ray], params: &StreamParams) -> Result<StreamPlan, Error> {
        crate::stream::plan_only(&self.gpu, self.stream_kernels()?, scene, rays, params)
    }

    /// Traces `rays` into `hits` with a record capacity of `cap` node events per ray; returns the
    /// records (in ray order) and the batches' GPU seconds.
    fn trace_with_cap(
        &self,
        scene: &WgpuScene,
        rays: &[Ray],
        options: &TraceOptions,
        cap: usize,
        hits: &mut [Hit],
    ) -> Result<batch::StreamOut, Error> {
        let pipeline = self.pipelines.get(&self.gpu, &launch::variant(scene, options, &self.config))?;
        let launch = launch::launch(scene, options, cap, &pipeline, &self.pipelines.bind_layout, self.config)?;
        let mut ws = scene.workspace()?;
        let Some(arranged) = Arranged::of(options.method, rays) else {
            return batch::run(&self.gpu, &mut ws, &launch, rays, hits);
        };
        let mut slot_hits = vec![Hit::MISS; arranged.rays.len()];
        let out = batch::run(&self.gpu, &mut ws, &launch, &arranged.rays, &mut slot_hits)?;
        arranged.restore(&slot_hits, 1, hits);
        let stride = launch.params.record_stride as usize;
        let mut records = vec![0u32; rays.len() * stride];
        arranged.restore(&out.records, stride, &mut records);
        Ok(batch::StreamOut { records, gpu_seconds: out.gpu_seconds })
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

    /// A hit list per ray on the device (shaders/all_hits.wgsl), on the tree the core's walk reads.
    fn all_hits(&self, scene: &WgpuScene, rays: &[Ray], options: &AllHitsOptions) -> Result<AllHits, Error> {
        self.trace_all_hits(scene, rays, options)
    }

    /// A query point per invocation (shaders/nearest.wgsl), on the tree the core's walk reads.
    fn nearest_points(
        &self,
        scene: &WgpuScene,
        points: &[[f32; 3]],
        radius: f32,
    ) -> Result<Vec<Option<NearestPoint>>, Error> {
        self.trace_nearest_points(scene, points, radius)
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
        let out = self.trace_with_cap(scene, rays, options, DEFAULT_RECORD_CAP, hits)?;
        let stride = launch::record_stride(options, DEFAULT_RECORD_CAP);
        let mut report = Report::new(rays.len(), start.elapsed().as_secs_f64());
        report.kernel_seconds = out.gpu_seconds;
        report.transfer_bytes = bytes_moved(rays.len(), stride);
        if options.record == Record::Nothing {
            return Ok(report);
        }
        let records = out.records;
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
                let mut h2 = vec![Hit::MISS; again.len()];
                let r2 = self.trace_with_cap(scene, &again, options, cap, &mut h2)?.records;
                let s2 = launch::record_stride(options, cap);
                let (mut still, mut still_counts) = (Vec::new(), Vec::new());
                for (k, &i) in overflowed.iter().enumerate() {
                    if !h2[k].same_as(&hits[i]) {
                        return Err(device_error(format!(
                            "{}: ray {i} found a different hit when traced again ({:?}, then {:?})",
                            options.method.name(),
                            hits[i],
                            h2[k]
                        )));
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
