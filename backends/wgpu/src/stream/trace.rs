//! A whole stream trace on the device: the plan, localized intersection, and the report.

use super::compose::StreamKernel;
use super::kernels::StreamKernels;
use super::plan::{plan, read_plan, GpuPlan};
use super::run::{Fixed, Run, StageUniform};
use crate::device::{device_error, Gpu};
use crate::params::Params;
use crate::record;
use crate::scene::WgpuScene;
use raytrail_core::method::StreamMethod;
use raytrail_core::observe::Counters;
use raytrail_core::stream::pipeline::{StageSeconds, StreamPlan};
use raytrail_core::stream::{Frustum, StreamParams, StreamScene, StreamStats};
use raytrail_core::trace::{Record, Report, TraceOptions};
use raytrail_core::{Error, Hit, Ray};
use wgpu::util::DeviceExt;

/// Sets up the trace's fixed buffers: parameters, rays, hits, records (`record_stride` words
/// per ray), the level-order tree.
fn start<'a>(
    gpu: &'a Gpu,
    kernels: &'a StreamKernels,
    scene: &'a WgpuScene,
    method: StreamMethod,
    rays: &[Ray],
    record_stride: usize,
) -> Result<(Run<'a>, StreamScene<'a>), Error> {
    let s = scene.prepared.stream_scene(method)?;
    let levels = scene
        .levels
        .as_ref()
        .ok_or(Error::NotPrepared { method: method.name(), missing: "the level-order tree on the device" })?;
    let n =
        u32::try_from(rays.len()).map_err(|_| device_error(format!("{} rays exceed 32-bit indices", rays.len())))?;
    let params = Params {
        ray_count: n,
        scene_scale: s.scene_scale,
        record_stride: record_stride as u32,
        kd_tris: levels.tris,
        ..Params::default()
    };
    let device = &gpu.device;
    let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("stream params"),
        contents: bytemuck::bytes_of(&params),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let ray_bytes: &[u8] = if rays.is_empty() { &[0u8; 32] } else { bytemuck::cast_slice(rays) };
    let check = |label: &str, bytes: u64| {
        let limit = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
        if bytes > limit {
            return Err(device_error(format!("{label} need {bytes} bytes, above the adapter's limit of {limit}")));
        }
        Ok(bytes.max(16))
    };
    check("the rays", ray_bytes.len() as u64)?;
    let rays_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("stream rays"),
        contents: ray_bytes,
        usage: wgpu::BufferUsages::STORAGE,
    });
    let rw = |label: &str, bytes: u64| -> Result<wgpu::Buffer, Error> {
        Ok(device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: check(label, bytes)?,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        }))
    };
    let hits = rw("the hits", 16 * rays.len() as u64)?;
    let records = rw("the records", 4 * rays.len() as u64 * record_stride as u64)?;
    let fixed = Fixed { params, rays: rays_buffer, hits, empty: &scene.empty, levels: &levels.buffer, records };
    Ok((Run::new(gpu, kernels, fixed)?, s))
}

/// Stages one to three of `rays` on the device, read back (what tests/stream_stages.rs checks).
pub(crate) fn plan_only(
    gpu: &Gpu,
    kernels: &StreamKernels,
    scene: &WgpuScene,
    rays: &[Ray],
    params: &StreamParams,
) -> Result<StreamPlan, Error> {
    gpu.checked("planning with the stream method", || {
        let (mut run, s) = start(gpu, kernels, scene, StreamMethod::Frustum8, rays, 0)?;
        let n = rays.len() as u32;
        let p = plan(&mut run, &s, n, params)?;
        read_plan(&mut run, &p, rays)
    })?
}

/// Traces `rays` into `hits` with the stream method.
pub(crate) fn trace(
    gpu: &Gpu,
    kernels: &StreamKernels,
    scene: &WgpuScene,
    method: StreamMethod,
    rays: &[Ray],
    options: &TraceOptions,
    hits: &mut [Hit],
) -> Result<Report, Error> {
    let start = std::time::Instant::now();
    let mut report = gpu.checked("tracing with the stream method", || {
        trace_checked(gpu, kernels, scene, method, rays, options, hits)
    })??;
    // End to end, the plan's read-backs and the host's share included; the kernels' own time is
    // the stages' timestamps.
    report.seconds = start.elapsed().as_secs_f64();
    Ok(report)
}

fn trace_checked(
    gpu: &Gpu,
    kernels: &StreamKernels,
    scene: &WgpuScene,
    method: StreamMethod,
    rays: &[Ray],
    options: &TraceOptions,
    hits: &mut [Hit],
) -> Result<Report, Error> {
    let stride = if options.record == Record::Nothing { 0 } else { record::stride(0) };
    let (mut run, s) = start(gpu, kernels, scene, method, rays, stride)?;
    let n = rays.len() as u32;
    let p = plan(&mut run, &s, n, &options.stream)?;
    run.next_stage(3)?;
    let l = &p.lists;
    // Rounds of at most `split_leaves` leaves per invocation, enough for the longest list.
    let ranges = run.read(&[(&l.ranges, 0, 2 * p.packets)])?.pop().unwrap_or_default();
    let largest_list = ranges.chunks_exact(2).map(|r| r[1]).max().unwrap_or(0);
    let per = options.stream.split_leaves.max(1);
    for round in 0..largest_list.div_ceil(per).max(1) {
        let mut stage = StageUniform::items(n).a(p.packets);
        stage.v[0] = [round, per, 0, 0];
        run.dispatch(StreamKernel::intersect(method, options), n, stage, &[&p.order, &p.bounds, &l.ranges, &l.node])?;
    }
    let (hit_buffer, record_buffer) = run.outputs();
    let (hit_buffer, record_buffer) = (hit_buffer.clone(), record_buffer.clone());
    // Both fit 32-bit word counts: `start` bounded their bytes by a binding's size.
    let words = |per_ray: usize| u32::try_from(rays.len() * per_ray).map_err(|_| device_error("too many rays"));
    let back = run.read(&[(&hit_buffer, 0, words(4)?), (&record_buffer, 0, words(stride)?)])?;
    run.next_stage(3)?;
    hits.copy_from_slice(bytemuck::cast_slice(&back[0]));
    let (seconds, timed) = run.seconds();
    let stats = StreamStats {
        packets: p.packets as usize,
        active_frustums: l.active as usize,
        queue_sizes: l.queue_sizes.clone(),
        leaf_refs: l.len as usize,
        largest_list: largest_list as usize,
        box_tests: l.box_tests,
        // The CPU's figure less its gathered copy of the rays: the device reads them through `order`.
        working_bytes: 4 * (2 * rays.len() + p.packets as usize + 1)
            + p.packets as usize * core::mem::size_of::<Frustum>()
            + 2 * 8 * l.biggest as usize,
        seconds: StageSeconds {
            sort: seconds[0],
            frustums: seconds[1],
            traversal: seconds[2],
            intersection: seconds[3],
        },
    };
    let mut report = Report::new(rays.len(), 0.0);
    report.kernel_seconds = timed.then(|| seconds.iter().sum());
    report.transfer_bytes = crate::workspace::bytes_moved(rays.len(), stride);
    if options.record != Record::Nothing {
        let mut counters = Counters { rays: rays.len() as u64, ..Counters::default() };
        for slot in back[1].chunks(stride) {
            record::add_counters(&mut counters, slot);
        }
        report.counters = Some(counters);
    }
    if options.record == Record::Enumerations {
        report.enumerations = Some(enumerations(&mut run, scene, method, &p, n)?);
    }
    report.stream = Some(stats);
    Ok(report)
}

/// Per ray: its packet, then the canonical ids of the packet's leaves in order (the core's
/// enumeration of the method), from the device's order, packet bounds, ranges and final queue.
fn enumerations(
    run: &mut Run<'_>,
    scene: &WgpuScene,
    method: StreamMethod,
    p: &GpuPlan,
    n: u32,
) -> Result<Vec<Vec<u32>>, Error> {
    let tree = scene.prepared.stream_scene(method)?.tree;
    let l = &p.lists;
    let back = run.read(&[
        (&p.order, 0, n),
        (&p.bounds, 0, p.packets + 1),
        (&l.ranges, 0, 2 * p.packets),
        (&l.node, 0, l.len),
    ])?;
    let (order, bounds, ranges, nodes) = (&back[0], &back[1], &back[2], &back[3]);
    let mut out = vec![Vec::new(); n as usize];
    let corrupt = || device_error("the stream method's read-back arrays are inconsistent");
    for (packet, range) in ranges.chunks_exact(2).enumerate() {
        let leaves = nodes.get(range[0] as usize..(range[0] as usize + range[1] as usize)).ok_or_else(corrupt)?;
        let mut list = vec![packet as u32];
        list.extend(leaves.iter().map(|&leaf| tree.canonical_id(leaf)));
        let (start, end) = (bounds.get(packet).ok_or_else(corrupt)?, bounds.get(packet + 1).ok_or_else(corrupt)?);
        let rays = order.get(*start as usize..*end as usize).ok_or_else(corrupt)?;
        for &ray in rays {
            *out.get_mut(ray as usize).ok_or_else(corrupt)? = list.clone();
        }
    }
    Ok(out)
}
