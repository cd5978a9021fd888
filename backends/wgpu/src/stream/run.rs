//! One stream trace on the device: its buffers, the kernels' dispatches recorded into a command
//! encoder, submissions where the host needs a count back, and the stages' GPU time.

use super::compose::StreamKernel;
use super::kernels::{StreamKernels, STAGE_ARRAYS};
use crate::batch::read;
use crate::device::{device_error, Gpu};
use bytemuck::{Pod, Zeroable};
use raytrail_core::Error;
use std::time::Instant;
use wgpu::util::DeviceExt;

/// Invocations per workgroup of every stream kernel (`STREAM_GROUP` in stream_common.wgsl).
pub(crate) const GROUP: u32 = 256;

/// Passes timed between two submissions; passes beyond it leave the stage untimed by the GPU.
const TIMED_PASSES: u32 = 512;

/// The per-dispatch uniform (`Stage` in shaders/stream_common.wgsl, 64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct StageUniform {
    pub n: u32,
    pub row_width: u32,
    pub a: u32,
    pub b: u32,
    pub v: [[u32; 4]; 3],
}

impl StageUniform {
    /// `n` items, the rest zero.
    pub fn items(n: u32) -> StageUniform {
        StageUniform { n, ..StageUniform::default() }
    }

    /// With the first scalar set.
    pub fn a(self, a: u32) -> StageUniform {
        StageUniform { a, ..self }
    }

    /// With the second scalar set.
    pub fn b(self, b: u32) -> StageUniform {
        StageUniform { b, ..self }
    }
}

/// The buffers bound at the prelude's bindings 0-6 for the whole trace.
pub(crate) struct Fixed<'a> {
    pub params: wgpu::Buffer,
    pub rays: wgpu::Buffer,
    pub hits: wgpu::Buffer,
    /// Bound at the BVH2 and hash bindings, which no stream kernel reads.
    pub empty: &'a wgpu::Buffer,
    /// The level-order tree (shaders/stream_levels.wgsl).
    pub levels: &'a wgpu::Buffer,
    pub records: wgpu::Buffer,
}

/// GPU timestamps of the passes recorded since the last submission.
struct Timer {
    set: wgpu::QuerySet,
    /// The stage of each timed pass.
    stages: Vec<usize>,
    /// Whether every pass so far was timed.
    complete: bool,
    seconds: [f64; 4],
}

/// A trace in progress.
pub(crate) struct Run<'a> {
    gpu: &'a Gpu,
    kernels: &'a StreamKernels,
    fixed: Fixed<'a>,
    /// Bound where a kernel has fewer arrays than the layout.
    spare: wgpu::Buffer,
    encoder: Option<wgpu::CommandEncoder>,
    timer: Option<Timer>,
    stage: usize,
    stage_start: Instant,
    wall: [f64; 4],
}

impl<'a> Run<'a> {
    pub fn new(gpu: &'a Gpu, kernels: &'a StreamKernels, fixed: Fixed<'a>) -> Result<Run<'a>, Error> {
        let timer = gpu.timestamps.then(|| Timer {
            set: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("stream stage times"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * TIMED_PASSES,
            }),
            stages: Vec::new(),
            complete: true,
            seconds: [0.0; 4],
        });
        let spare = array(gpu, "stream spare", 4)?;
        Ok(Run {
            gpu,
            kernels,
            fixed,
            spare,
            encoder: None,
            timer,
            stage: 0,
            stage_start: Instant::now(),
            wall: [0.0; 4],
        })
    }

    /// A zeroed read-write array of `words` u32 (at least one word: bindings must not be empty).
    pub fn array(&self, label: &str, words: u64) -> Result<wgpu::Buffer, Error> {
        array(self.gpu, label, words)
    }

    fn encoder(&mut self) -> &mut wgpu::CommandEncoder {
        let device = &self.gpu.device;
        self.encoder.get_or_insert_with(|| {
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("stream") })
        })
    }

    /// Runs `kernel` with `invocations` invocations (rounded up to whole workgroups) over `arrays`
    /// (bindings 8 and up); nothing for none.
    pub fn dispatch(
        &mut self,
        kernel: StreamKernel,
        invocations: u32,
        mut stage: StageUniform,
        arrays: &[&wgpu::Buffer],
    ) -> Result<(), Error> {
        if invocations == 0 {
            return Ok(());
        }
        if arrays.len() > STAGE_ARRAYS {
            return Err(device_error(format!("{} binds {} arrays", kernel.label(), arrays.len())));
        }
        let groups = invocations.div_ceil(GROUP);
        let max_x = self.gpu.limits.max_compute_workgroups_per_dimension;
        let x = groups.min(max_x);
        let y = groups.div_ceil(x);
        if y > max_x {
            return Err(device_error(format!("{invocations} invocations exceed one dispatch")));
        }
        stage.row_width = x * GROUP;
        let pipeline = self.kernels.get(self.gpu, kernel)?;
        let device = &self.gpu.device;
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("stream stage"),
            contents: bytemuck::bytes_of(&stage),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let f = &self.fixed;
        let mut entries = vec![
            wgpu::BindGroupEntry { binding: 0, resource: f.params.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: f.rays.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: f.hits.as_entire_binding() },
            // The level-order tree twice, as shaders/stream_levels.wgsl reads it.
            wgpu::BindGroupEntry { binding: 3, resource: f.levels.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 4, resource: f.empty.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 5, resource: f.levels.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 6, resource: f.records.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 7, resource: uniform.as_entire_binding() },
        ];
        for i in 0..STAGE_ARRAYS {
            let b = arrays.get(i).copied().unwrap_or(&self.spare);
            entries.push(wgpu::BindGroupEntry { binding: 8 + i as u32, resource: b.as_entire_binding() });
        }
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("stream"),
            layout: &self.kernels.bind_layout,
            entries: &entries,
        });
        let label = kernel.label();
        let stage_index = self.stage;
        let timer = &mut self.timer;
        let writes = match timer {
            Some(t) if (t.stages.len() as u32) < TIMED_PASSES => {
                let i = t.stages.len() as u32;
                t.stages.push(stage_index);
                Some((i * 2, &t.set))
            }
            Some(t) => {
                t.complete = false;
                None
            }
            None => None,
        };
        let timestamp_writes = writes.map(|(i, set)| wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(i),
            end_of_pass_write_index: Some(i + 1),
        });
        let encoder = self.encoder.get_or_insert_with(|| {
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("stream") })
        });
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(&label), timestamp_writes });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(x, y, 1);
        Ok(())
    }

    /// Copies `words` words of `from` into `to` (same offsets).
    pub fn copy(&mut self, from: &wgpu::Buffer, to: &wgpu::Buffer, words: u32) {
        if words > 0 {
            self.encoder().copy_buffer_to_buffer(from, 0, to, 0, u64::from(words) * 4);
        }
    }

    /// Writes `value` at word `at` of `to` before the next submission's commands.
    pub fn write_word(&self, to: &wgpu::Buffer, at: u32, value: u32) {
        self.gpu.queue.write_buffer(to, u64::from(at) * 4, bytemuck::bytes_of(&value));
    }

    /// Submits what was recorded and waits for it, adding the timed passes to their stages.
    pub fn flush(&mut self) -> Result<(), Error> {
        self.read(&[]).map(|_| ())
    }

    /// Submits what was recorded, then reads back `count` words from word `at` of each buffer.
    pub fn read(&mut self, what: &[(&wgpu::Buffer, u32, u32)]) -> Result<Vec<Vec<u32>>, Error> {
        let device = &self.gpu.device;
        let staging: Vec<(wgpu::Buffer, usize)> = what
            .iter()
            .map(|&(_, _, count)| {
                let bytes = (u64::from(count) * 4).max(4);
                let b = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("stream read-back"),
                    size: bytes.next_multiple_of(4),
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                (b, count as usize)
            })
            .collect();
        for (&(from, at, count), (to, _)) in what.iter().zip(&staging) {
            if count > 0 {
                self.encoder().copy_buffer_to_buffer(from, u64::from(at) * 4, to, 0, u64::from(count) * 4);
            }
        }
        let times = match &self.timer {
            Some(t) if !t.stages.is_empty() => {
                let n = t.stages.len() as u32 * 2;
                let bytes = u64::from(n) * 8;
                let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("stream timestamps"),
                    size: bytes,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                });
                let back = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("stream timestamps read-back"),
                    size: bytes,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                let set = t.set.clone();
                let enc = self.encoder();
                enc.resolve_query_set(&set, 0..n, &resolve, 0);
                enc.copy_buffer_to_buffer(&resolve, 0, &back, 0, bytes);
                Some((back, n as usize))
            }
            _ => None,
        };
        if let Some(enc) = self.encoder.take() {
            self.gpu.queue.submit([enc.finish()]);
        }
        let mut out = Vec::with_capacity(staging.len());
        for (b, count) in &staging {
            out.push(if *count == 0 { Vec::new() } else { read::<u32>(self.gpu, b, *count)? });
        }
        if let (Some((back, n)), Some(t)) = (times, self.timer.as_mut()) {
            let stamps = read::<u64>(self.gpu, &back, n)?;
            let period = f64::from(self.gpu.queue.get_timestamp_period()) * 1e-9;
            for (pair, &stage) in stamps.chunks(2).zip(&t.stages) {
                t.seconds[stage] += pair[1].saturating_sub(pair[0]) as f64 * period;
            }
            t.stages.clear();
        }
        Ok(out)
    }

    /// One word of `buffer`.
    pub fn read_word(&mut self, buffer: &wgpu::Buffer, at: u32) -> Result<u32, Error> {
        Ok(self.read(&[(buffer, at, 1)])?[0][0])
    }

    /// Ends the current stage (its work submitted and waited for) and starts stage `next`
    /// (0 sort, 1 frustums, 2 traversal, 3 intersection).
    pub fn next_stage(&mut self, next: usize) -> Result<(), Error> {
        self.flush()?;
        self.wall[self.stage] += self.stage_start.elapsed().as_secs_f64();
        self.stage = next;
        self.stage_start = Instant::now();
        Ok(())
    }

    /// Seconds per stage: GPU time where every pass was timed, wall-clock time otherwise; and
    /// whether they are GPU time.
    pub fn seconds(&self) -> ([f64; 4], bool) {
        match &self.timer {
            Some(t) if t.complete => (t.seconds, true),
            _ => (self.wall, false),
        }
    }

    /// The hits and records buffers, for reading back at the end.
    pub fn outputs(&self) -> (&wgpu::Buffer, &wgpu::Buffer) {
        (&self.fixed.hits, &self.fixed.records)
    }
}

fn usage() -> wgpu::BufferUsages {
    wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST
}

fn check_size(gpu: &Gpu, label: &str, words: u64) -> Result<(), Error> {
    let bytes = words.saturating_mul(4);
    let limit = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
    if bytes > limit {
        return Err(device_error(format!(
            "{label} needs {bytes} bytes, above the adapter's storage binding limit of {limit} bytes"
        )));
    }
    Ok(())
}

fn array(gpu: &Gpu, label: &str, words: u64) -> Result<wgpu::Buffer, Error> {
    check_size(gpu, label, words)?;
    Ok(gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: words.max(4) * 4,
        usage: usage(),
        mapped_at_creation: false,
    }))
}
