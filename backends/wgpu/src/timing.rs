//! Kernel time at steady clocks: the rays are uploaded once, then many passes over them run back
//! to back in one submission between two timestamps, after a warm-up long enough for the GPU to
//! leave its idle clocks. A trace call's own figures ([`Report`](raytrail_core::trace::Report))
//! are the end-to-end ones.

use crate::backend::WgpuBackend;
use crate::batch::{self, Launch, Stamps};
use crate::device::{device_error, Gpu};
use crate::launch::{self, Arranged};
use crate::scene::WgpuScene;
use crate::workspace::bytes_moved;
use crate::workspace::{SlotNeeds, Workspace};
use raytrail_core::method::Method;
use raytrail_core::method::WideWalk;
use raytrail_core::trace::{Record, Trace, TraceOptions};
use raytrail_core::{Error, Hit, Ray};
use std::time::{Duration, Instant};

/// How [`WgpuBackend::time_kernel`] measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimingPlan {
    /// Untimed passes run at least this long first (GPUs raise their clocks under sustained load).
    pub warm_up: Duration,
    /// Timed submissions; each gives one sample.
    pub samples: usize,
    /// Passes per submission are chosen so that one lasts about this long.
    pub sample_length: Duration,
}

impl Default for TimingPlan {
    fn default() -> Self {
        TimingPlan { warm_up: Duration::from_millis(500), samples: 5, sample_length: Duration::from_millis(100) }
    }
}

/// Kernel time of one method over one set of rays.
#[derive(Clone, Debug, PartialEq)]
pub struct KernelTiming {
    /// Rays per pass.
    pub rays: usize,
    /// Seconds per pass over all the rays, one per sample (each the mean of
    /// [`KernelTiming::passes_per_sample`] back-to-back passes).
    pub seconds: Vec<f64>,
    /// Passes per timed submission.
    pub passes_per_sample: usize,
    /// Wall-clock seconds of the warm-up.
    pub warm_up_seconds: f64,
    /// Bytes one trace call of these rays moves between host and device (not moved while timing:
    /// the passes reuse the rays on the device).
    pub bytes_per_trace: u64,
}

impl KernelTiming {
    /// Millions of rays per second of each sample, ascending.
    pub fn mrays_per_s(&self) -> Vec<f64> {
        let mut m: Vec<f64> =
            self.seconds.iter().map(|&s| if s > 0.0 { self.rays as f64 / s / 1e6 } else { 0.0 }).collect();
        m.sort_by(f64::total_cmp);
        m
    }

    /// The median sample's millions of rays per second (0 without samples).
    pub fn median_mrays_per_s(&self) -> f64 {
        let m = self.mrays_per_s();
        match m.len() {
            0 => 0.0,
            n if n % 2 == 1 => m[n / 2],
            n => 0.5 * (m[n / 2 - 1] + m[n / 2]),
        }
    }

    /// The slowest and fastest samples' millions of rays per second.
    pub fn spread(&self) -> (f64, f64) {
        let m = self.mrays_per_s();
        (m.first().copied().unwrap_or(0.0), m.last().copied().unwrap_or(0.0))
    }
}

/// The batches of one timed method, uploaded to their slots.
struct Uploaded {
    /// Per batch: its slot, workgroups in x and y, and rays.
    batches: Vec<(usize, (u32, u32), usize)>,
}

impl WgpuBackend {
    /// Times the kernel of `options` over `rays` at steady clocks (see the module's text);
    /// [`Error::Device`] where the adapter has no timestamp queries. The stream method is timed
    /// by whole traces (its stages' timestamps), since its passes depend on each other's sizes;
    /// so is `bvh8-lists`, whose streams may take rounds the host waits for.
    /// Records nothing: `options.record` is ignored.
    pub fn time_kernel(
        &self,
        scene: &WgpuScene,
        rays: &[Ray],
        options: &TraceOptions,
        plan: &TimingPlan,
    ) -> Result<KernelTiming, Error> {
        if !self.gpu.timestamps {
            return Err(device_error(format!("adapter '{}' has no timestamp queries", self.gpu.info.name)));
        }
        if plan.samples == 0 {
            return Err(Error::InvalidParameter { name: "samples", why: "at least one sample is needed" });
        }
        if rays.is_empty() {
            return Err(Error::InvalidParameter { name: "rays", why: "timing needs at least one ray" });
        }
        let options = options.record(Record::Nothing);
        if matches!(options.method, Method::Stream(_))
            || options.method.wide().is_some_and(|m| m.walk() == WideWalk::RayLists)
        {
            return self.time_whole_traces(scene, rays, &options, plan);
        }
        let pipeline = self.pipelines.get(&self.gpu, &launch::variant(scene, &options, &self.config))?;
        let launch = launch::launch(scene, &options, 0, &pipeline, &self.pipelines.bind_layout, self.config)?;
        let arranged = Arranged::of(options.method, rays);
        let work = arranged.as_ref().map_or(rays, |a| &a.rays);
        let mut ws = scene.workspace()?;
        let gpu = &self.gpu;
        gpu.checked("timing a kernel", || -> Result<KernelTiming, Error> {
            let up = upload(gpu, &mut ws, &launch, work)?;
            let queries = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("kernel timing"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            });
            let start = Instant::now();
            let mut per_pass = passes(gpu, &mut ws, &launch, &up, &queries, 1)?;
            while start.elapsed() < plan.warm_up {
                per_pass = passes(gpu, &mut ws, &launch, &up, &queries, 1)?;
            }
            let warm_up_seconds = start.elapsed().as_secs_f64();
            let per_sample =
                (plan.sample_length.as_secs_f64() / per_pass.max(1e-9)).ceil().clamp(1.0, 10_000.0) as usize;
            let mut seconds = Vec::with_capacity(plan.samples);
            for _ in 0..plan.samples {
                seconds.push(passes(gpu, &mut ws, &launch, &up, &queries, per_sample)?);
            }
            Ok(KernelTiming {
                rays: rays.len(),
                seconds,
                passes_per_sample: per_sample,
                warm_up_seconds,
                bytes_per_trace: bytes_moved(rays.len(), 0),
            })
        })?
    }

    /// [`WgpuBackend::time_kernel`] for the stream methods: whole traces, each sample the sum of
    /// its stages' (or rounds') timestamps.
    fn time_whole_traces(
        &self,
        scene: &WgpuScene,
        rays: &[Ray],
        options: &TraceOptions,
        plan: &TimingPlan,
    ) -> Result<KernelTiming, Error> {
        let mut hits = vec![Hit::MISS; rays.len()];
        let start = Instant::now();
        self.trace(scene, rays, options, &mut hits)?;
        while start.elapsed() < plan.warm_up {
            self.trace(scene, rays, options, &mut hits)?;
        }
        let warm_up_seconds = start.elapsed().as_secs_f64();
        let mut seconds = Vec::with_capacity(plan.samples);
        for _ in 0..plan.samples {
            let r = self.trace(scene, rays, options, &mut hits)?;
            seconds.push(r.kernel_seconds.ok_or_else(|| device_error("a stream stage was not timed"))?);
        }
        Ok(KernelTiming {
            rays: rays.len(),
            seconds,
            passes_per_sample: 1,
            warm_up_seconds,
            bytes_per_trace: bytes_moved(rays.len(), 0),
        })
    }
}

/// Uploads `rays` batch by batch, one slot each, with each batch's parameters.
fn upload(gpu: &Gpu, ws: &mut Workspace, launch: &Launch<'_>, rays: &[Ray]) -> Result<Uploaded, Error> {
    let per_batch = batch::batch_rays(gpu, launch);
    let max_bytes = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
    let mut batches = Vec::new();
    for (b, chunk) in rays.chunks(per_batch).enumerate() {
        let n = chunk.len();
        let d = batch::grid(gpu, launch, n.div_ceil(launch.rays_per_item))?;
        let params = d.params(launch.params, n);
        let need = SlotNeeds { rays: n, record_words: 0, scratch_bytes: launch.scratch_bytes(n) };
        let slot = ws.slot(gpu, b, need, max_bytes);
        slot.unmap_leftovers();
        gpu.queue.write_buffer(&slot.uniform, 0, bytemuck::bytes_of(&params));
        // The loop guard's flag, zeroed once: any timed pass that raises it is seen.
        gpu.queue.write_buffer(&slot.scratch, 0, &[0u8; batch::DISPATCH_STATE_BYTES as usize]);
        gpu.queue.write_buffer(&slot.rays, 0, bytemuck::cast_slice(chunk));
        batches.push((b, (d.x, d.y), n));
    }
    Ok(Uploaded { batches })
}

/// Runs `count` passes over every uploaded batch in one submission; returns GPU seconds per pass.
fn passes(
    gpu: &Gpu,
    ws: &mut Workspace,
    launch: &Launch<'_>,
    up: &Uploaded,
    queries: &wgpu::QuerySet,
    count: usize,
) -> Result<f64, Error> {
    let max_bytes = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
    let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("timed passes") });
    let last = count * up.batches.len() - 1;
    for k in 0..count * up.batches.len() {
        let (slot_index, (x, y), _) = up.batches[k % up.batches.len()];
        let slot = ws.slot(gpu, slot_index, SlotNeeds::default(), max_bytes);
        let stamps = Stamps::Around { queries, begin: k == 0, end: k == last };
        batch::encode(gpu, &mut enc, launch, slot, (x, y), stamps);
    }
    let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("timed passes' stamps"),
        size: 16,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let back = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("timed passes' stamps read-back"),
        size: 16,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    enc.resolve_query_set(queries, 0..2, &resolve, 0);
    enc.copy_buffer_to_buffer(&resolve, 0, &back, 0, 16);
    // The loop guard's flag (shaders/loop_guard.wgsl), zeroed at the upload and raised by any pass
    // of the batch whose loops were cut: a time is not reported for walks the device cut short
    // (unlike a trace, timing does not trace such a batch again with one item per SIMD group).
    for &(slot_index, _, _) in &up.batches {
        let slot = ws.slot(gpu, slot_index, SlotNeeds::default(), max_bytes);
        enc.copy_buffer_to_buffer(&slot.scratch, 0, &slot.scratch_back, 0, batch::DISPATCH_STATE_BYTES);
    }
    gpu.queue.submit([enc.finish()]);
    let stamps = batch::read::<u64>(gpu, &back, 2)?;
    for &(slot_index, _, rays) in &up.batches {
        let slot = ws.slot(gpu, slot_index, SlotNeeds::default(), max_bytes);
        let state = batch::read::<u32>(gpu, &slot.scratch_back, 4)?;
        if batch::loops_were_cut(&state) {
            return Err(batch::loops_cut(rays));
        }
    }
    let period = f64::from(gpu.queue.get_timestamp_period()) * 1e-9;
    Ok(stamps[1].saturating_sub(stamps[0]) as f64 * period / count as f64)
}
