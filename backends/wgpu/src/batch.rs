//! A stream of ray batches on the device: each batch is uploaded, dispatched and copied to its
//! slot's read-back buffers in one submission, and up to `in_flight` batches are submitted before
//! the oldest one is waited for, so that the device works on one batch while the host fills the
//! next and empties the previous.

use crate::config::{Dispatch, GpuConfig, CPU_ADAPTER_ROUNDS, CPU_ADAPTER_STREAM_STEPS, MAX_PERSISTENT_ROUNDS};
use crate::device::{device_error, Gpu};
use crate::params::Params;
use crate::workspace::{SceneBindings, Slot, SlotNeeds, Workspace, HIT_BYTES};
use bytemuck::Pod;
use raytrail_core::method::{Method, WideWalk};
use raytrail_core::{Error, Hit, Ray};
use std::collections::VecDeque;
use std::sync::mpsc;

/// Everything a stream of batches shares: the kernel, what it binds and its parameters.
pub(crate) struct Launch<'a> {
    pub pipeline: &'a wgpu::ComputePipeline,
    pub bind_layout: &'a wgpu::BindGroupLayout,
    /// The bind-group cache key: a method binds the same scene buffers every time.
    pub method: Method,
    pub scene: SceneBindings<'a>,
    /// Per-scene parameters; the batch fills in its own counts.
    pub params: Params,
    /// Rays per work item (1, the packet width, or the stream's rays).
    pub rays_per_item: usize,
    /// Kernel scratch bytes per work item (the stream kernel's lists), beyond the item counter.
    pub scratch_per_item: u64,
    pub config: GpuConfig,
}

impl Launch<'_> {
    /// Kernel scratch bytes for a batch of `rays` rays: the unfinished count's 16 bytes, then
    /// each item's.
    pub fn scratch_bytes(&self, rays: usize) -> u64 {
        match self.scratch_per_item {
            0 => 0,
            bytes => 16 + rays.div_ceil(self.rays_per_item.max(1)) as u64 * bytes,
        }
    }
}

/// What a stream of batches returns besides the hits.
pub(crate) struct StreamOut {
    /// `record_stride` words per ray, in ray order (empty when nothing is recorded).
    pub records: Vec<u32>,
    /// GPU seconds summed over the batches' passes, when every batch was timed.
    pub gpu_seconds: Option<f64>,
}

/// Rays per batch for `launch`: the configured size within the device's binding and dispatch
/// limits, a multiple of the rays per item.
pub(crate) fn batch_rays(gpu: &Gpu, launch: &Launch<'_>) -> usize {
    let l = &gpu.limits;
    let stride = launch.params.record_stride.max(1) as usize;
    let binding = (l.max_storage_buffer_binding_size.min(l.max_buffer_size) as usize).max(64);
    let by_binding = (binding / 32).min(binding / (4 * stride));
    // Whole items of scratch within one binding.
    let per_item = launch.rays_per_item.max(1);
    let by_scratch = match launch.scratch_per_item as usize {
        0 => usize::MAX,
        bytes => (binding / bytes).max(1) * per_item,
    };
    let by_dispatch = l.max_compute_workgroups_per_dimension as usize * launch.config.workgroup_size as usize * 1024;
    let n = launch.config.batch_rays.min(by_binding).min(by_scratch).min(by_dispatch).max(per_item);
    n - n % per_item
}

/// Rounds a persistent workgroup fetches at most on `gpu` (see [`CPU_ADAPTER_ROUNDS`]).
fn persistent_rounds(gpu: &Gpu) -> usize {
    if gpu.info.device_type == wgpu::DeviceType::Cpu {
        CPU_ADAPTER_ROUNDS
    } else {
        MAX_PERSISTENT_ROUNDS
    }
}

/// The dispatch of `items` work items: workgroups in x and y, the grid's row width, and the rounds
/// a persistent workgroup fetches at most (the workgroups cover the items within them).
pub(crate) fn grid(gpu: &Gpu, launch: &Launch<'_>, items: usize) -> Result<Dispatched, Error> {
    spread_grid(gpu, launch, items, Spread::One)
}

/// How many invocations a work item gets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Spread {
    /// One: every invocation takes an item.
    One,
    /// [`SPREAD_ON_CUT`], in one round: a batch whose loops were cut, traced again.
    OnePerGroup,
}

/// Invocations per item when a batch whose loops the device cut short is traced again: at least
/// the widest SIMD group of llvmpipe (16 lanes of 32 bits with AVX-512), so that each group runs
/// the loops of one item only.
const SPREAD_ON_CUT: usize = 16;

/// [`grid`] with `spread` invocations per item.
fn spread_grid(gpu: &Gpu, launch: &Launch<'_>, items: usize, spread: Spread) -> Result<Dispatched, Error> {
    let wg = launch.config.workgroup_size as usize;
    let (per_item, rounds) = match spread {
        Spread::One => (1, persistent_rounds(gpu)),
        Spread::OnePerGroup => (SPREAD_ON_CUT, 1),
    };
    let items = items.saturating_mul(per_item);
    // `launch` resolved the dispatch for its method (`Dispatch::for_method`): never `ByMethod` here.
    let groups = match launch.config.dispatch {
        Dispatch::Grid | Dispatch::ByMethod => items.div_ceil(wg),
        Dispatch::Persistent { workgroups } => {
            (workgroups as usize).max(items.div_ceil(wg * rounds)).min(items.div_ceil(wg))
        }
    }
    .max(1);
    let max_x = gpu.limits.max_compute_workgroups_per_dimension as usize;
    let x = groups.min(max_x);
    let y = groups.div_ceil(x);
    if y > max_x {
        return Err(device_error(format!("{items} work items exceed one dispatch (batching failed)")));
    }
    Ok(Dispatched {
        x: x as u32,
        y: y as u32,
        row_width: (x * wg) as u32,
        rounds: rounds as u32,
        spread: per_item as u32,
    })
}

/// What [`grid`] decides.
pub(crate) struct Dispatched {
    pub x: u32,
    pub y: u32,
    pub row_width: u32,
    pub rounds: u32,
    /// Invocations per item.
    pub spread: u32,
}

impl Dispatched {
    /// The batch's parameters: `base` with its ray count and the dispatch's figures.
    pub fn params(&self, base: Params, rays: usize) -> Params {
        Params {
            ray_count: rays as u32,
            row_width: self.row_width,
            persistent_rounds: self.rounds,
            item_spread: self.spread,
            ..base
        }
    }
}

/// A submitted batch waiting to be read back.
struct Pending {
    slot: usize,
    /// Its first ray in the stream, and its rays.
    first: usize,
    rays: usize,
    submission: wgpu::SubmissionIndex,
    /// One result per buffer mapped (hits, then records, timestamps and the dispatch state where
    /// present).
    mapped: Vec<mpsc::Receiver<Result<(), wgpu::BufferAsyncError>>>,
}

/// Starts mapping `buffer`'s first `bytes` for reading; the receiver gets the outcome.
fn map(buffer: &wgpu::Buffer, bytes: u64) -> mpsc::Receiver<Result<(), wgpu::BufferAsyncError>> {
    let (tx, rx) = mpsc::channel();
    buffer.slice(..bytes).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    rx
}

/// Copies `buffer`'s first `out.len()` values into `out` (the buffer is mapped) and unmaps it.
fn take<T: Pod>(buffer: &wgpu::Buffer, out: &mut [T]) -> Result<(), Error> {
    let bytes = std::mem::size_of_val(out) as u64;
    if bytes > 0 {
        let view = buffer
            .slice(..bytes)
            .get_mapped_range()
            .map_err(|e| device_error(format!("reading a mapped buffer: {e:?}")))?;
        out.copy_from_slice(bytemuck::cast_slice(&view));
    }
    buffer.unmap();
    Ok(())
}

/// Which timestamps a batch's pass writes.
pub(crate) enum Stamps<'q> {
    /// Its slot's two, around the pass (where the slot has queries).
    Slot,
    /// Of its slot's two, the first before the pass if `begin`, the second after it if `end`
    /// (timestamps around several rounds).
    SlotPart { begin: bool, end: bool },
    /// Into `queries`: index 0 before the pass if `begin`, index 1 after it if `end` (timestamps
    /// around many passes).
    Around { queries: &'q wgpu::QuerySet, begin: bool, end: bool },
}

/// Records one batch's pass in `enc`: the persistent item counter zeroed first, then the pass.
/// The loop guard's flag is the caller's to zero, once for all the passes it reads it after.
pub(crate) fn encode(
    gpu: &Gpu,
    enc: &mut wgpu::CommandEncoder,
    launch: &Launch<'_>,
    slot: &mut Slot,
    dims: (u32, u32),
    stamps: Stamps<'_>,
) {
    if let Dispatch::Persistent { .. } = launch.config.dispatch {
        enc.clear_buffer(&slot.scratch, 0, Some(4));
    }
    let bind = slot.bind_group(gpu, launch.bind_layout, launch.method, &launch.scene).clone();
    let timestamp_writes = match stamps {
        Stamps::Slot => slot.timer.as_ref().map(|t| wgpu::ComputePassTimestampWrites {
            query_set: &t.queries,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        }),
        Stamps::SlotPart { begin, end } => {
            slot.timer.as_ref().filter(|_| begin || end).map(|t| wgpu::ComputePassTimestampWrites {
                query_set: &t.queries,
                beginning_of_pass_write_index: begin.then_some(0),
                end_of_pass_write_index: end.then_some(1),
            })
        }
        Stamps::Around { queries, begin, end } => (begin || end).then_some(wgpu::ComputePassTimestampWrites {
            query_set: queries,
            beginning_of_pass_write_index: begin.then_some(0),
            end_of_pass_write_index: end.then_some(1),
        }),
    };
    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("trace"), timestamp_writes });
    pass.set_pipeline(launch.pipeline);
    pass.set_bind_group(0, &bind, &[]);
    pass.dispatch_workgroups(dims.0, dims.1, 1);
}

/// Traces `rays` in batches into `hits` (one per ray), keeping `in_flight` batches on the device.
pub(crate) fn run(
    gpu: &Gpu,
    ws: &mut Workspace,
    launch: &Launch<'_>,
    rays: &[Ray],
    hits: &mut [Hit],
) -> Result<StreamOut, Error> {
    let stride = launch.params.record_stride as usize;
    let mut records = vec![0u32; rays.len() * stride];
    let mut gpu_seconds = Some(0.0);
    if rays.is_empty() {
        return Ok(StreamOut { records, gpu_seconds });
    }
    let per_batch = batch_rays(gpu, launch);
    let max_bytes = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
    let period = f64::from(gpu.queue.get_timestamp_period()) * 1e-9;
    let mut pending: VecDeque<Pending> = VecDeque::new();
    // Waits for batch `p` and copies out its results; true if the loop guard found its loops cut.
    let mut finish = |p: Pending, hits: &mut [Hit], records: &mut [u32], ws: &mut Workspace| -> Result<bool, Error> {
        gpu.device
            .poll(wgpu::PollType::Wait { submission_index: Some(p.submission), timeout: None })
            .map_err(|e| device_error(format!("waiting for the device: {e}")))?;
        for rx in &p.mapped {
            rx.recv()
                .map_err(|_| device_error("the read-back callback never ran"))?
                .map_err(|e| device_error(format!("mapping a read-back buffer: {e}")))?;
        }
        let slot = ws.slot(gpu, p.slot, SlotNeeds::default(), max_bytes);
        // Each buffer read is unmapped; what a failure leaves mapped is unmapped before the slot's
        // next batch (`Slot::unmap_leftovers`).
        take(&slot.hit_back, &mut hits[p.first..p.first + p.rays])?;
        slot.mapped &= !1;
        if stride > 0 {
            take(&slot.record_back, &mut records[p.first * stride..(p.first + p.rays) * stride])?;
            slot.mapped &= !2;
        }
        if let Some(t) = &slot.timer {
            let mut stamps = [0u64; 2];
            take(&t.back, &mut stamps)?;
            slot.mapped &= !4;
            gpu_seconds = gpu_seconds.map(|s| s + stamps[1].saturating_sub(stamps[0]) as f64 * period);
        } else {
            gpu_seconds = None;
        }
        let mut state = [0u32; 4];
        if slot.mapped & 8 != 0 {
            take(&slot.scratch_back, &mut state)?;
            slot.mapped &= !8;
        }
        Ok(loops_were_cut(&state))
    };
    // `finish`, and a batch whose loops were cut traced again with one item per SIMD group of
    // invocations (lavapipe's limit counts the loops of all the items a group runs: persistent
    // rounds, and the neighbours of a long item); if that is cut too, an error. The kernel seconds
    // then include both passes: the device spent them on this trace. The wide packet kernel's item
    // is a whole workgroup, which no spread divides: a cut there is an error at once.
    let spreads = !launch.method.wide().is_some_and(|m| m.walk() == WideWalk::Packet);
    let mut settle = |p: Pending, hits: &mut [Hit], records: &mut [u32], ws: &mut Workspace| -> Result<(), Error> {
        let (slot, first, n) = (p.slot, p.first, p.rays);
        if !finish(p, hits, records, ws)? {
            return Ok(());
        }
        if !spreads {
            return Err(loops_cut(n));
        }
        let again = submit(gpu, ws, launch, slot, &rays[first..first + n], first, Spread::OnePerGroup)?;
        if finish(again, hits, records, ws)? {
            return Err(loops_cut(n));
        }
        Ok(())
    };
    gpu.checked("tracing a stream of batches", || -> Result<(), Error> {
        for (b, chunk) in rays.chunks(per_batch).enumerate() {
            let slot_index = b % launch.config.in_flight;
            if pending.len() >= launch.config.in_flight {
                if let Some(p) = pending.pop_front() {
                    settle(p, hits, &mut records, ws)?;
                }
            }
            pending.push_back(submit(gpu, ws, launch, slot_index, chunk, b * per_batch, Spread::One)?);
        }
        while let Some(p) = pending.pop_front() {
            settle(p, hits, &mut records, ws)?;
        }
        Ok(())
    })??;
    Ok(StreamOut { records, gpu_seconds })
}

/// Uploads `chunk` (the stream's rays from `first` on) to slot `slot_index`, dispatches it with
/// `spread` invocations per item, and starts reading back its hits, records, timestamps and
/// dispatch state.
fn submit(
    gpu: &Gpu,
    ws: &mut Workspace,
    launch: &Launch<'_>,
    slot_index: usize,
    chunk: &[Ray],
    first: usize,
    spread: Spread,
) -> Result<Pending, Error> {
    let stride = launch.params.record_stride as usize;
    let max_bytes = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
    let n = chunk.len();
    let items = n.div_ceil(launch.rays_per_item);
    let d = spread_grid(gpu, launch, items, spread)?;
    let params = d.params(launch.params, n);
    let need = SlotNeeds { rays: n, record_words: n * stride, scratch_bytes: launch.scratch_bytes(n) };
    let slot = ws.slot(gpu, slot_index, need, max_bytes);
    slot.unmap_leftovers();
    gpu.queue.write_buffer(&slot.uniform, 0, bytemuck::bytes_of(&params));
    gpu.queue.write_buffer(&slot.rays, 0, bytemuck::cast_slice(chunk));
    if launch.scratch_per_item > 0 {
        rounds_of_streams(gpu, launch, slot, params, (d.x, d.y))?;
    }
    let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("batch") });
    // The kernels of the dispatch files and the wide packet kernel carry the loop guard; the
    // stream kernel's rounds read the scratch themselves.
    let guarded = launch.scratch_per_item == 0;
    if guarded {
        // The flag and the words after it; `encode` zeroes the persistent item counter before it.
        enc.clear_buffer(
            &slot.scratch,
            LOOPS_CUT_WORD as u64 * 4,
            Some(DISPATCH_STATE_BYTES - LOOPS_CUT_WORD as u64 * 4),
        );
        encode(gpu, &mut enc, launch, slot, (d.x, d.y), Stamps::Slot);
        enc.copy_buffer_to_buffer(&slot.scratch, 0, &slot.scratch_back, 0, DISPATCH_STATE_BYTES);
    }
    let hit_bytes = n as u64 * HIT_BYTES;
    enc.copy_buffer_to_buffer(&slot.hits, 0, &slot.hit_back, 0, hit_bytes);
    let record_bytes = (n * stride * 4) as u64;
    if record_bytes > 0 {
        enc.copy_buffer_to_buffer(&slot.records, 0, &slot.record_back, 0, record_bytes);
    }
    if let Some(t) = &slot.timer {
        enc.resolve_query_set(&t.queries, 0..2, &t.resolve, 0);
        enc.copy_buffer_to_buffer(&t.resolve, 0, &t.back, 0, 16);
    }
    let submission = gpu.queue.submit([enc.finish()]);
    let mut mapped = vec![map(&slot.hit_back, hit_bytes)];
    slot.mapped = 1;
    if record_bytes > 0 {
        mapped.push(map(&slot.record_back, record_bytes));
        slot.mapped |= 2;
    }
    if let Some(t) = &slot.timer {
        mapped.push(map(&t.back, 16));
        slot.mapped |= 4;
    }
    if guarded {
        mapped.push(map(&slot.scratch_back, DISPATCH_STATE_BYTES));
        slot.mapped |= 8;
    }
    Ok(Pending { slot: slot_index, first, rays: n, submission, mapped })
}

/// Bytes of the dispatch state at the start of the kernel's scratch (shaders/loop_guard.wgsl's
/// `DispatchState`: the persistent item counter, then the loop guard's flag), rounded to 16.
pub(crate) const DISPATCH_STATE_BYTES: u64 = 16;

/// The word of the dispatch state that holds the loop guard's flag (`DispatchState::loops_cut`).
const LOOPS_CUT_WORD: usize = 1;

/// Whether the dispatch state read back from a pass (its first words) has the loop guard's flag
/// raised.
pub(crate) fn loops_were_cut(state: &[u32]) -> bool {
    state.get(LOOPS_CUT_WORD).is_some_and(|&flag| flag != 0)
}

/// The error for a batch of `rays` rays whose loops the device cut short, even with one item per
/// SIMD group of invocations. Mesa's llvmpipe ends a SIMD group's loops once they have run 65,535
/// iterations in all and says nothing; the walks it cut report misses, so the trace fails rather
/// than succeed with them (what the hits buffer holds after the error is not an answer, as after
/// any error).
pub(crate) fn loops_cut(rays: usize) -> Error {
    device_error(format!(
        "the device cut the kernel's loops short in a batch of {rays} rays (Mesa's llvmpipe ends a \
         group of invocations' loops after 65,535 iterations in all), so its hits would be \
         incomplete; trace these rays with a method of shorter walks or on another adapter"
    ))
}

/// The stream kernel's rounds over one batch (shaders/wide_ray_stream.wgsl): dispatched, each on
/// its own and waited for, until no stream is left unfinished; the slot's timestamps span them
/// all. On a GPU one round does it; a CPU adapter takes [`CPU_ADAPTER_STREAM_STEPS`] steps a
/// round. Every round takes a step at least, and a stream at most nine per node it visits (the
/// visit, its copy and up to seven pops), so `9 * max_steps` steps bound the rounds.
fn rounds_of_streams(
    gpu: &Gpu,
    launch: &Launch<'_>,
    slot: &mut Slot,
    params: Params,
    dims: (u32, u32),
) -> Result<(), Error> {
    let steps = if gpu.info.device_type == wgpu::DeviceType::Cpu { CPU_ADAPTER_STREAM_STEPS } else { u32::MAX };
    let most = 9 * u64::from(params.max_steps) / u64::from(steps) + 2;
    for round in 0..most {
        let p = Params { stream_round: round.min(u64::from(u32::MAX)) as u32, stream_steps: steps, ..params };
        gpu.queue.write_buffer(&slot.uniform, 0, bytemuck::bytes_of(&p));
        let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("round") });
        enc.clear_buffer(&slot.scratch, 0, Some(16));
        encode(gpu, &mut enc, launch, slot, dims, Stamps::SlotPart { begin: round == 0, end: true });
        enc.copy_buffer_to_buffer(&slot.scratch, 0, &slot.scratch_back, 0, 16);
        gpu.queue.submit([enc.finish()]);
        if read::<u32>(gpu, &slot.scratch_back, 1)?[0] == 0 {
            return Ok(());
        }
    }
    Err(device_error(format!("the stream kernel left streams unfinished after {most} rounds")))
}

/// Reads `count` values of `T` from the start of the read-back `buffer` (for one-off reads such as
/// the numerics probe's and the stream method's).
pub(crate) fn read<T: Pod>(gpu: &Gpu, buffer: &wgpu::Buffer, count: usize) -> Result<Vec<T>, Error> {
    let rx = map(buffer, (count * std::mem::size_of::<T>()).max(4) as u64);
    gpu.device
        .poll(wgpu::PollType::Wait { submission_index: None, timeout: None })
        .map_err(|e| device_error(format!("waiting for the device: {e}")))?;
    rx.recv()
        .map_err(|_| device_error("the read-back callback never ran"))?
        .map_err(|e| device_error(format!("mapping a read-back buffer: {e}")))?;
    let mut out = vec![T::zeroed(); count];
    take(buffer, &mut out)?;
    Ok(out)
}
