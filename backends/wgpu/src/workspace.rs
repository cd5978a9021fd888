//! Per-scene device buffers kept between trace calls: a ring of batch slots, each with its ray,
//! hit, record and read-back buffers and its bind groups, grown when a batch needs more and
//! otherwise reused, so that tracing again allocates nothing.

use crate::device::Gpu;
use crate::params::Params;
use raytrail_core::method::Method;
use std::collections::HashMap;

/// Bytes of one ray and one hit on the device.
pub(crate) const RAY_BYTES: u64 = 32;
pub(crate) const HIT_BYTES: u64 = 16;

/// Bytes a trace of `rays` rays moves between host and device: rays up, hits and `stride` record
/// words per ray down.
pub(crate) fn bytes_moved(rays: usize, stride: usize) -> u64 {
    rays as u64 * (RAY_BYTES + HIT_BYTES + 4 * stride as u64)
}

/// One batch's buffers. A slot is reused only after its previous batch has been read back.
pub(crate) struct Slot {
    pub uniform: wgpu::Buffer,
    pub rays: wgpu::Buffer,
    pub hits: wgpu::Buffer,
    pub records: wgpu::Buffer,
    /// The kernel's scratch: the dispatch state (the persistent kernels' item counter and the
    /// loop guard's flag, zeroed before every dispatch), or the stream kernel's lists.
    pub scratch: wgpu::Buffer,
    pub hit_back: wgpu::Buffer,
    pub record_back: wgpu::Buffer,
    /// The scratch's first 16 bytes read back (the stream kernel's unfinished streams, or the
    /// dispatch state with the loop guard's flag).
    pub scratch_back: wgpu::Buffer,
    /// Two timestamps around the batch's pass, resolved and read back with the hits.
    pub timer: Option<Timer>,
    /// Rays the buffers hold.
    pub ray_capacity: usize,
    /// Record words the buffers hold.
    pub record_capacity: usize,
    /// Bytes the scratch holds.
    pub scratch_capacity: u64,
    /// Bind groups by method (a method binds the same scene buffers every time).
    binds: HashMap<Method, wgpu::BindGroup>,
    /// Read-back buffers mapped or being mapped and not yet read: bit 0 hits, 1 records, 2 the
    /// timestamps, 3 the scratch's first 16 bytes.
    pub mapped: u8,
}

/// A slot's timestamp queries.
pub(crate) struct Timer {
    pub queries: wgpu::QuerySet,
    pub resolve: wgpu::Buffer,
    pub back: wgpu::Buffer,
}

/// The scene buffers a kernel binds besides the slot's own.
pub(crate) struct SceneBindings<'a> {
    pub bvh: &'a wgpu::Buffer,
    pub hash: &'a wgpu::Buffer,
    pub kd: &'a wgpu::Buffer,
}

/// What a batch needs of its slot: rays, record words, scratch bytes.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SlotNeeds {
    pub rays: usize,
    pub record_words: usize,
    pub scratch_bytes: u64,
}

/// The ring of slots of one scene, and how many buffers it has ever created.
#[derive(Default)]
pub(crate) struct Workspace {
    slots: Vec<Slot>,
    created: u64,
}

/// Capacity rounded up so that slowly growing batches do not reallocate every call.
fn grown(needed: usize) -> usize {
    needed.max(1).next_power_of_two()
}

impl Workspace {
    /// Buffers (and query sets) created since the scene was uploaded.
    pub fn created(&self) -> u64 {
        self.created
    }

    /// Slot `i`, with room for what `need` says; made or grown as needed. `max_bytes` is the
    /// device's largest binding.
    pub fn slot(&mut self, gpu: &Gpu, i: usize, need: SlotNeeds, max_bytes: u64) -> &mut Slot {
        while self.slots.len() <= i {
            let slot = self.make(gpu, SlotNeeds::default(), max_bytes);
            self.slots.push(slot);
        }
        let s = &self.slots[i];
        if s.ray_capacity < need.rays
            || s.record_capacity < need.record_words
            || s.scratch_capacity < need.scratch_bytes
        {
            let grown = SlotNeeds {
                rays: s.ray_capacity.max(need.rays),
                record_words: s.record_capacity.max(need.record_words),
                scratch_bytes: s.scratch_capacity.max(need.scratch_bytes),
            };
            self.slots[i] = self.make(gpu, grown, max_bytes);
        }
        &mut self.slots[i]
    }

    /// A slot for what `need` says, capacities rounded up within `max_bytes`.
    fn make(&mut self, gpu: &Gpu, need: SlotNeeds, max_bytes: u64) -> Slot {
        let SlotNeeds { rays, record_words, scratch_bytes } = need;
        // Rounded up for growth, but not past the largest binding unless the batch itself needs it
        // (batches are sized to fit), and never empty.
        let cap = |n: usize, unit: u64| (grown(n) as u64 * unit).min(max_bytes).max(n as u64 * unit).max(16);
        let ray_bytes = cap(rays, RAY_BYTES);
        let hit_bytes = cap(rays, HIT_BYTES);
        let record_bytes = cap(record_words, 4);
        let ray_capacity = ((ray_bytes / RAY_BYTES) as usize).min((hit_bytes / HIT_BYTES) as usize);
        let record_capacity = (record_bytes / 4) as usize;
        use wgpu::BufferUsages as U;
        let uniform = self.buffer(gpu, "params", std::mem::size_of::<Params>() as u64, U::UNIFORM | U::COPY_DST);
        let rays_buf = self.buffer(gpu, "rays", ray_bytes, U::STORAGE | U::COPY_DST);
        let hits = self.buffer(gpu, "hits", hit_bytes, U::STORAGE | U::COPY_SRC | U::COPY_DST);
        let records = self.buffer(gpu, "records", record_bytes, U::STORAGE | U::COPY_SRC);
        // Not rounded up: the stream kernel's lists are large, and a batch's size rarely changes.
        let scratch_capacity = scratch_bytes.max(16);
        let scratch = self.buffer(gpu, "kernel scratch", scratch_capacity, U::STORAGE | U::COPY_DST | U::COPY_SRC);
        let hit_back = self.buffer(gpu, "hits read-back", hit_bytes, U::MAP_READ | U::COPY_DST);
        let record_back = self.buffer(gpu, "records read-back", record_bytes, U::MAP_READ | U::COPY_DST);
        let scratch_back = self.buffer(gpu, "scratch read-back", 16, U::MAP_READ | U::COPY_DST);
        let timer = gpu.timestamps.then(|| {
            self.created += 1;
            Timer {
                queries: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("batch time"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 2,
                }),
                resolve: self.buffer(gpu, "timestamps", 16, U::QUERY_RESOLVE | U::COPY_SRC),
                back: self.buffer(gpu, "timestamps read-back", 16, U::MAP_READ | U::COPY_DST),
            }
        });
        Slot {
            uniform,
            rays: rays_buf,
            hits,
            records,
            scratch,
            hit_back,
            record_back,
            scratch_back,
            timer,
            ray_capacity,
            record_capacity,
            scratch_capacity,
            binds: HashMap::new(),
            mapped: 0,
        }
    }

    fn buffer(&mut self, gpu: &Gpu, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.created += 1;
        gpu.device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
    }
}

impl Slot {
    /// Unmaps read-back buffers a failed trace left mapped (or waiting to be), so that the slot can
    /// take a new batch.
    pub fn unmap_leftovers(&mut self) {
        let backs = [
            Some(&self.hit_back),
            Some(&self.record_back),
            self.timer.as_ref().map(|t| &t.back),
            Some(&self.scratch_back),
        ];
        for (bit, b) in backs.into_iter().enumerate() {
            if let Some(b) = b.filter(|_| self.mapped & (1 << bit) != 0) {
                b.unmap();
            }
        }
        self.mapped = 0;
    }

    /// The bind group of `method` over this slot's buffers and `scene`'s, made on first use.
    pub fn bind_group(
        &mut self,
        gpu: &Gpu,
        layout: &wgpu::BindGroupLayout,
        method: Method,
        scene: &SceneBindings<'_>,
    ) -> &wgpu::BindGroup {
        let Slot { uniform, rays, hits, records, scratch, binds, .. } = self;
        binds.entry(method).or_insert_with(|| {
            fn e(binding: u32, b: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
                wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() }
            }
            gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("raytrail batch"),
                layout,
                entries: &[
                    e(0, uniform),
                    e(1, rays),
                    e(2, hits),
                    e(3, scene.bvh),
                    e(4, scene.hash),
                    e(5, scene.kd),
                    e(6, records),
                    e(7, scratch),
                ],
            })
        })
    }
}
