//! One batch of rays on the device: upload, dispatch, read back.

use crate::device::{device_error, Gpu};
use crate::params::Params;
use bytemuck::Pod;
use raytrail_core::{Error, Hit, Ray};
use wgpu::util::DeviceExt;

/// What a batch returns.
pub(crate) struct BatchOut {
    pub hits: Vec<Hit>,
    /// `records` words (empty when nothing is recorded).
    pub records: Vec<u32>,
    /// GPU seconds from timestamp queries, when the adapter has them.
    pub gpu_seconds: Option<f64>,
}

/// The buffers a kernel binds besides the batch's own.
pub(crate) struct SceneBindings<'a> {
    pub bvh: &'a wgpu::Buffer,
    pub hash: &'a wgpu::Buffer,
    pub kd: &'a wgpu::Buffer,
}

fn storage_rw(gpu: &Gpu, label: &str, bytes: u64) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

fn readback(gpu: &Gpu, bytes: u64) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

pub(crate) fn read<T: Pod>(gpu: &Gpu, buffer: &wgpu::Buffer, count: usize) -> Result<Vec<T>, Error> {
    let slice = buffer.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    gpu.device
        .poll(wgpu::PollType::Wait { submission_index: None, timeout: None })
        .map_err(|e| device_error(format!("waiting for the device: {e}")))?;
    rx.recv()
        .map_err(|_| device_error("the read-back callback never ran"))?
        .map_err(|e| device_error(format!("mapping a read-back buffer: {e}")))?;
    let view = slice.get_mapped_range().map_err(|e| device_error(format!("reading a mapped buffer: {e:?}")))?;
    let all: &[T] = bytemuck::cast_slice(&view);
    let out = all[..count].to_vec();
    drop(view);
    buffer.unmap();
    Ok(out)
}

/// Runs `pipeline` over `rays` with `invocations` invocations (one per ray, or one per packet).
pub(crate) fn run(
    gpu: &Gpu,
    pipeline: &wgpu::ComputePipeline,
    bind_layout: &wgpu::BindGroupLayout,
    scene: &SceneBindings<'_>,
    mut params: Params,
    rays: &[Ray],
    invocations: usize,
) -> Result<BatchOut, Error> {
    const WORKGROUP: usize = 64;
    let groups = invocations.div_ceil(WORKGROUP).max(1);
    let max_x = gpu.limits.max_compute_workgroups_per_dimension as usize;
    let x = groups.min(max_x);
    let y = groups.div_ceil(x);
    if y > max_x {
        return Err(device_error(format!("{invocations} invocations exceed one dispatch (batching failed)")));
    }
    params.ray_count = rays.len() as u32;
    params.row_width = (x * WORKGROUP) as u32;
    let n = rays.len();
    let record_words = n * params.record_stride as usize;
    let d = &gpu.device;
    gpu.checked("tracing a batch", || -> Result<BatchOut, Error> {
        let uniform = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let ray_bytes: &[u8] = if rays.is_empty() { &[0u8; 32] } else { bytemuck::cast_slice(rays) };
        let ray_buf = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("rays"),
            contents: ray_bytes,
            usage: wgpu::BufferUsages::STORAGE,
        });
        let hit_bytes = (n * 16) as u64;
        let hit_buf = storage_rw(gpu, "hits", hit_bytes);
        let rec_bytes = (record_words * 4) as u64;
        let rec_buf = storage_rw(gpu, "records", rec_bytes);
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("raytrail batch"),
            layout: bind_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: ray_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: hit_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: scene.bvh.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: scene.hash.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 5, resource: scene.kd.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 6, resource: rec_buf.as_entire_binding() },
            ],
        });
        let queries = gpu.timestamps.then(|| {
            d.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("trace time"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            })
        });
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("trace") });
        {
            let timestamp_writes = queries.as_ref().map(|q| wgpu::ComputePassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: Some(1),
            });
            let mut pass =
                enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("trace"), timestamp_writes });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(x as u32, y as u32, 1);
        }
        let hit_back = readback(gpu, hit_bytes);
        enc.copy_buffer_to_buffer(&hit_buf, 0, &hit_back, 0, hit_bytes.max(16));
        let rec_back = (record_words > 0).then(|| {
            let b = readback(gpu, rec_bytes);
            enc.copy_buffer_to_buffer(&rec_buf, 0, &b, 0, rec_bytes);
            b
        });
        let time_back = queries.as_ref().map(|q| {
            let resolve = d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps"),
                size: 16,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            enc.resolve_query_set(q, 0..2, &resolve, 0);
            let back = readback(gpu, 16);
            enc.copy_buffer_to_buffer(&resolve, 0, &back, 0, 16);
            back
        });
        gpu.queue.submit([enc.finish()]);
        let hits = read::<Hit>(gpu, &hit_back, n)?;
        let records = match &rec_back {
            Some(b) => read::<u32>(gpu, b, record_words)?,
            None => Vec::new(),
        };
        let gpu_seconds = match &time_back {
            Some(b) => {
                let t = read::<u64>(gpu, b, 2)?;
                Some(t[1].saturating_sub(t[0]) as f64 * f64::from(gpu.queue.get_timestamp_period()) * 1e-9)
            }
            None => None,
        };
        Ok(BatchOut { hits, records, gpu_seconds })
    })?
}
