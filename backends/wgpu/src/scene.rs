//! A prepared scene on the device: each layout and table the scene was prepared with, uploaded
//! once, and nothing it was not.

use crate::device::{device_error, Gpu};
use crate::workspace::Workspace;
use raytrail_core::bvh2::{BinaryLayout, LeafWord};
use raytrail_core::method::{Bvh2Method, WideMethod, WideTreeKind};
use raytrail_core::prepared::{BuiltHash, PreparedScene};
use raytrail_core::wide::WideBvh;
use raytrail_core::Error;
use std::sync::{Arc, Mutex, MutexGuard};
use wgpu::util::DeviceExt;

/// A BVH2 layout on the device: internal nodes, then the leaf array.
pub(crate) struct LayoutBuffer {
    pub buffer: wgpu::Buffer,
    /// Where the leaf array starts, in 16-byte words.
    pub leaf_base: u32,
}

/// Hash tables on the device: displacements, then cells.
pub(crate) struct HashBuffer {
    pub buffer: wgpu::Buffer,
    pub d_mask: u32,
    pub h: u32,
}

/// The kd-tree on the device: nodes, references, triangles.
pub(crate) struct KdBuffer {
    pub buffer: wgpu::Buffer,
    pub prims: u32,
    pub tris: u32,
}

/// A wide tree (or the stream's level-order tree) on the device: nodes, then each triangle as
/// three 16-byte entries, the primitive id in the first one's fourth word (the BVH2 leaf's
/// triangle entries), which the kernels read 16 bytes at a time (shaders/wide.wgsl).
pub(crate) struct WideBuffer {
    pub buffer: wgpu::Buffer,
    /// Where the triangle entries start, in words (a multiple of four).
    pub tris: u32,
}

/// A scene as the wgpu backend holds it.
pub struct WgpuScene {
    /// The prepared scene (the host side: roots, layouts for canonical ids, key width).
    pub prepared: Arc<PreparedScene>,
    pub(crate) uncles: Option<LayoutBuffer>,
    pub(crate) parents: Option<LayoutBuffer>,
    pub(crate) hash: Option<HashBuffer>,
    pub(crate) full_hash: Option<HashBuffer>,
    pub(crate) kd: Option<KdBuffer>,
    /// The wide trees.
    pub(crate) wide4: Option<WideBuffer>,
    /// The hash over the 4-wide tree's node keys (bvh4-hash).
    pub(crate) wide4_hash: Option<HashBuffer>,
    pub(crate) wide8: Option<WideBuffer>,
    pub(crate) wide4_naive: Option<WideBuffer>,
    pub(crate) wide8_sah: Option<WideBuffer>,
    /// The stream method's level-order tree, laid out as the wide trees are: nodes (eight words
    /// each, `LevelNode`), then the triangle entries.
    pub(crate) levels: Option<WideBuffer>,
    /// A small buffer bound where a kernel's unused bindings would be.
    pub(crate) empty: wgpu::Buffer,
    /// Batch buffers kept between traces (every method but the stream method, whose stage arrays
    /// are sized by each call's rays).
    workspace: Mutex<Workspace>,
}

fn storage(gpu: &Gpu, label: &str, words: &[u32]) -> Result<wgpu::Buffer, Error> {
    let bytes = (words.len() as u64) * 4;
    if bytes > gpu.limits.max_storage_buffer_binding_size || bytes > gpu.limits.max_buffer_size {
        return Err(device_error(format!(
            "{label} needs {bytes} bytes, above the adapter's storage binding limit of {} bytes",
            gpu.limits.max_storage_buffer_binding_size
        )));
    }
    // Bindings must not be empty.
    let padded;
    let contents: &[u32] = if words.is_empty() {
        padded = [0u32; 4];
        &padded
    } else {
        words
    };
    gpu.checked(label, || {
        gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::cast_slice(contents),
            usage: wgpu::BufferUsages::STORAGE,
        })
    })
}

fn layout(gpu: &Gpu, label: &str, l: &BinaryLayout) -> Result<LayoutBuffer, Error> {
    let mut words: Vec<u32> = Vec::with_capacity(l.nodes.len() * 16 + l.leaves.len() * 4);
    words.extend_from_slice(bytemuck::cast_slice(&l.nodes));
    words.extend_from_slice(bytemuck::cast_slice(&l.leaves));
    let leaf_base = u32::try_from(l.nodes.len() * 4)
        .map_err(|_| device_error(format!("{label}: {} nodes exceed 32-bit word offsets", l.nodes.len())))?;
    Ok(LayoutBuffer { buffer: storage(gpu, label, &words)?, leaf_base })
}

/// Nodes, then primitive references, then triangles (nine words each), with the offsets of the
/// last two: the kd-tree's layout.
fn nodes_prims_triangles(
    gpu: &Gpu,
    label: &str,
    nodes: &[u32],
    prims: &[u32],
    triangles: &[raytrail_core::geometry::Triangle],
) -> Result<KdBuffer, Error> {
    let mut words = Vec::with_capacity(nodes.len() + prims.len() + triangles.len() * 9);
    words.extend_from_slice(nodes);
    words.extend_from_slice(prims);
    words.extend(triangles.iter().flat_map(|t| t.v).flat_map(|v| v.to_array()).map(f32::to_bits));
    let too_big = |_| device_error(format!("{label} exceeds 32-bit word offsets"));
    Ok(KdBuffer {
        buffer: storage(gpu, label, &words)?,
        prims: u32::try_from(nodes.len()).map_err(too_big)?,
        tris: u32::try_from(nodes.len() + prims.len()).map_err(too_big)?,
    })
}

/// Nodes, padded to 16 bytes, then the triangle entries of [`WideBuffer`].
fn nodes_triangle_entries(
    gpu: &Gpu,
    label: &str,
    nodes: &[u32],
    prims: &[u32],
    triangles: &[raytrail_core::geometry::Triangle],
) -> Result<WideBuffer, Error> {
    let tris = nodes.len().next_multiple_of(4);
    let mut words = Vec::with_capacity(tris + triangles.len() * 12);
    words.extend_from_slice(nodes);
    words.resize(tris, 0);
    for (t, &prim) in triangles.iter().zip(prims) {
        let entries = [
            LeafWord::vertex_entry(t.v[0], prim),
            LeafWord::vertex_entry(t.v[1], 0),
            LeafWord::vertex_entry(t.v[2], 0),
        ];
        words.extend_from_slice(bytemuck::cast_slice(&entries));
    }
    let tris = u32::try_from(tris).map_err(|_| device_error(format!("{label} exceeds 32-bit word offsets")))?;
    Ok(WideBuffer { buffer: storage(gpu, label, &words)?, tris })
}

fn wide<const W: usize>(gpu: &Gpu, label: &str, t: &WideBvh<W>) -> Result<WideBuffer, Error> {
    nodes_triangle_entries(gpu, label, bytemuck::cast_slice(t.nodes()), t.prims(), t.triangles())
}

fn hash(gpu: &Gpu, label: &str, h: &BuiltHash) -> Result<HashBuffer, Error> {
    let t = &h.tables;
    let mut words: Vec<u32> = Vec::with_capacity(t.displacement.len() + t.cells.len());
    words.extend(t.displacement.iter().map(|&d| d as u32));
    words.extend_from_slice(&t.cells);
    Ok(HashBuffer { buffer: storage(gpu, label, &words)?, d_mask: t.shape.d_mask, h: t.shape.h })
}

impl WgpuScene {
    /// Uploads what `prepared` holds.
    pub(crate) fn upload(gpu: &Gpu, prepared: Arc<PreparedScene>) -> Result<WgpuScene, Error> {
        let p = &prepared;
        let uncles = p.uncles.as_ref().map(|l| layout(gpu, "uncle layout", l)).transpose()?;
        let parents = p.parents.as_ref().map(|l| layout(gpu, "parent/sibling layout", l)).transpose()?;
        let hash_tables = p.hash.as_ref().map(|h| hash(gpu, "hash tables", h)).transpose()?;
        let full_hash = p.full_hash.as_ref().map(|h| hash(gpu, "full hash tables", h)).transpose()?;
        let kd =
            p.kd.as_ref()
                .map(|kd| {
                    nodes_prims_triangles(
                        gpu,
                        "kd-tree",
                        bytemuck::cast_slice(kd.tree.nodes()),
                        kd.tree.prims(),
                        &kd.triangles,
                    )
                })
                .transpose()?;
        let wide4 = p.wide4.as_ref().map(|t| wide(gpu, "4-wide BVH", t)).transpose()?;
        let wide4_hash = match &p.wide4_hash {
            Some(Ok(h)) => Some(hash(gpu, "4-wide key hash", &h.hash)?),
            _ => None,
        };
        let wide8 = p.wide8.as_ref().map(|t| wide(gpu, "8-wide BVH", t)).transpose()?;
        let wide4_naive = p.wide4_naive.as_ref().map(|t| wide(gpu, "naive 4-wide BVH", t)).transpose()?;
        let wide8_sah = p.wide8_sah.as_ref().map(|t| wide(gpu, "SAH-optimal 8-wide BVH", t)).transpose()?;
        let levels = p
            .levels
            .as_ref()
            .map(|t| {
                nodes_triangle_entries(
                    gpu,
                    "level-order tree",
                    bytemuck::cast_slice(t.nodes()),
                    t.prims(),
                    t.triangles(),
                )
            })
            .transpose()?;
        let empty = storage(gpu, "empty", &[])?;
        Ok(WgpuScene {
            prepared,
            uncles,
            parents,
            hash: hash_tables,
            full_hash,
            kd,
            wide4,
            wide4_hash,
            wide8,
            wide4_naive,
            wide8_sah,
            levels,
            empty,
            workspace: Mutex::new(Workspace::default()),
        })
    }

    /// Device buffers (and timestamp query sets) the scene's traces have created so far: a trace
    /// no larger than an earlier one creates none.
    pub fn buffers_created(&self) -> u64 {
        self.workspace.lock().map_or(0, |w| w.created())
    }

    /// The batch buffers, for one trace at a time.
    pub(crate) fn workspace(&self) -> Result<MutexGuard<'_, Workspace>, Error> {
        self.workspace
            .lock()
            .map_err(|_| device_error("the scene's batch buffers were poisoned by a panic in another thread"))
    }

    /// The layout buffer `method` reads.
    pub(crate) fn layout_for(&self, method: Bvh2Method) -> Option<&LayoutBuffer> {
        if method.needs_parent_links() {
            self.parents.as_ref()
        } else {
            self.uncles.as_ref()
        }
    }

    /// The hash buffer `method` reads, if any.
    pub(crate) fn hash_for(&self, method: Bvh2Method) -> Option<&HashBuffer> {
        if method.needs_full_hash() {
            self.full_hash.as_ref()
        } else if method.needs_hash() {
            self.hash.as_ref()
        } else {
            None
        }
    }

    /// The wide tree buffer `method` reads.
    pub(crate) fn wide_for(&self, method: WideMethod) -> Option<&WideBuffer> {
        match method.tree() {
            WideTreeKind::Four => self.wide4.as_ref(),
            WideTreeKind::Eight => self.wide8.as_ref(),
            WideTreeKind::FourNaive => self.wide4_naive.as_ref(),
            WideTreeKind::EightSah => self.wide8_sah.as_ref(),
        }
    }

    /// Bytes on the device.
    pub fn device_bytes(&self) -> u64 {
        let l = |b: &Option<LayoutBuffer>| b.as_ref().map_or(0, |b| b.buffer.size());
        let h = |b: &Option<HashBuffer>| b.as_ref().map_or(0, |b| b.buffer.size());
        let k = |b: &Option<KdBuffer>| b.as_ref().map_or(0, |b| b.buffer.size());
        let w = |b: &Option<WideBuffer>| b.as_ref().map_or(0, |b| b.buffer.size());
        l(&self.uncles)
            + l(&self.parents)
            + h(&self.hash)
            + h(&self.full_hash)
            + k(&self.kd)
            + w(&self.wide4)
            + h(&self.wide4_hash)
            + w(&self.wide8)
            + w(&self.wide4_naive)
            + w(&self.wide8_sah)
            + w(&self.levels)
    }
}
