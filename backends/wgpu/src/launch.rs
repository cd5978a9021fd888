//! What a trace of one method binds and sets: the scene's buffers for the method, the per-scene
//! parameters, and the packet kernels' arrangement of rays into packets.

use crate::batch::Launch;
use crate::compose::{Answer, DispatchKind, Variant};
use crate::config::{Dispatch, GpuConfig};
use crate::params::Params;
use crate::record;
use crate::scene::WgpuScene;
use crate::workspace::SceneBindings;
use raytrail_core::bvh2::NodeRef;
use raytrail_core::kd::traverse::packets::{packet_slots_of, PADDING};
use raytrail_core::kd::traverse::PACKET_WIDTH;
use raytrail_core::key::KeyWidth;
use raytrail_core::method::WideWalk;
use raytrail_core::method::{KdMethod, Method};
use raytrail_core::trace::{Record, TraceOptions};
use raytrail_core::wide::packet::WIDE_PACKET;
use raytrail_core::wide::traverse::WIDE_STACK;
use raytrail_core::wide::{WideChild, STREAM_RAYS};
use raytrail_core::{Error, Ray};

/// The kernel variant for `options` on `scene` under `config`.
pub(crate) fn variant(scene: &WgpuScene, options: &TraceOptions, config: &GpuConfig) -> Variant {
    let config = &for_method(options.method, *config);
    Variant {
        method: options.method,
        keys: keys_for(scene, options.method),
        triangle: options.triangle_test,
        query: options.query,
        record: options.record,
        dispatch: DispatchKind::of(config.dispatch, options.method),
        workgroup_size: config.workgroup_size,
        answer: Answer::Hit,
    }
}

/// The key width of `method`'s kernel: the 4-wide tree's for the trail walk, the binary
/// tree's otherwise (only the BVH2 stackless methods read it there).
fn keys_for(scene: &WgpuScene, method: Method) -> KeyWidth {
    match method.wide() {
        Some(m) if m.walk() == WideWalk::Trail => scene.prepared.wide_keyed(m).map_or(KeyWidth::W64, |(_, keys)| keys),
        _ => scene.prepared.key_width(),
    }
}

/// `config` as `method` runs under it: the dispatch resolved ([`Dispatch::for_method`]); the wide
/// packet and stream kernels take a packet or a stream to a workgroup, so their work items are
/// packets or streams handed out one workgroup each (`grid` counts workgroups as items per
/// workgroup size), on the grid.
fn for_method(method: Method, config: GpuConfig) -> GpuConfig {
    if shares_walks(method) {
        GpuConfig { workgroup_size: 1, dispatch: Dispatch::Grid, ..config }
    } else {
        GpuConfig { dispatch: config.dispatch.for_method(method), ..config }
    }
}

fn is_wide_packet(method: Method) -> bool {
    method.wide().is_some_and(|m| m.walk() == WideWalk::Packet)
}

fn is_wide_stream(method: Method) -> bool {
    method.wide().is_some_and(|m| m.walk() == WideWalk::RayLists)
}

/// Whether `method`'s kernel takes a packet or a stream of rays to a workgroup.
fn shares_walks(method: Method) -> bool {
    method.wide().is_some_and(|m| m.walk().shares_walks())
}

/// The stream kernel's scratch per stream (shaders/wide_ray_stream.wgsl, `WS_REGION`): a set of
/// one bit per ray for every stack entry, then the state a round saves (eight words, two per stack
/// entry, the current set).
const STREAM_SCRATCH_BYTES: u64 = 4 * (WIDE_STACK * STREAM_RAYS / 32 + 8 + 2 * WIDE_STACK + STREAM_RAYS / 32) as u64;

/// Record words per ray for `options` with room for `cap` node events.
pub(crate) fn record_stride(options: &TraceOptions, cap: usize) -> usize {
    match options.record {
        Record::Nothing => 0,
        Record::Counters => record::stride(0),
        Record::Enumerations => record::stride(cap),
    }
}

/// The launch of `pipeline` for `options` on `scene`, recording up to `cap` node events per ray.
pub(crate) fn launch<'a>(
    scene: &'a WgpuScene,
    options: &TraceOptions,
    cap: usize,
    pipeline: &'a wgpu::ComputePipeline,
    bind_layout: &'a wgpu::BindGroupLayout,
    config: GpuConfig,
) -> Result<Launch<'a>, Error> {
    let p = &scene.prepared;
    let stride = record_stride(options, cap);
    let mut params = Params { record_stride: stride as u32, record_cap: cap as u32, ..Params::default() };
    let scene_bindings = match options.method {
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
            let tree = scene.wide_for(m).ok_or(Error::NotPrepared { method: m.name(), missing: "its wide tree" })?;
            params.max_steps = root.max_steps;
            params.scene_scale = root.scene_scale;
            params.kd_tris = tree.tris;
            (params.root, params.wide_root_count) = match root.root {
                WideChild::Node(n) => (n, 0),
                WideChild::Leaf { first, count } => (NodeRef::leaf(first).0, count),
            };
            let hash = if m.walk() == WideWalk::Trail {
                // Fails with the scene's reason where it holds no tables (a tree too deep).
                p.wide_keyed(m)?;
                let missing = Error::NotPrepared { method: m.name(), missing: "its key hash" };
                let h = scene.wide4_hash.as_ref().ok_or(missing)?;
                params.d_mask = h.d_mask;
                params.h = h.h;
                &h.buffer
            } else {
                &scene.empty
            };
            // Bound twice: word by word for the nodes, 16 bytes at a time for the triangle entries
            // (shaders/wide.wgsl).
            SceneBindings { bvh: &tree.buffer, hash, kd: &tree.buffer }
        }
        other => return Err(Error::Unsupported { method: other.name(), by: "the wgpu backend" }),
    };
    let rays_per_item = match options.method {
        Method::Kd(KdMethod::Packet) => PACKET_WIDTH,
        m if is_wide_packet(m) => WIDE_PACKET,
        m if is_wide_stream(m) => STREAM_RAYS,
        _ => 1,
    };
    let scratch_per_item = if is_wide_stream(options.method) { STREAM_SCRATCH_BYTES } else { 0 };
    let config = for_method(options.method, config);
    Ok(Launch {
        pipeline,
        bind_layout,
        method: options.method,
        scene: scene_bindings,
        params,
        rays_per_item,
        scratch_per_item,
        config,
    })
}

/// A packet kernel's rays, grouped as the core groups them (every backend alike): slot `s` holds
/// ray `order[s]`, padding as untraceable rays, so that packet `p` is slots `width * p ..`
/// (`PACKET_WIDTH` for kd-packet, `WIDE_PACKET` for bvh8-packet).
pub(crate) struct Arranged {
    pub order: Vec<u32>,
    pub rays: Vec<Ray>,
}

impl Arranged {
    /// The arrangement of `rays` for `method`; `None` for every method but the packet ones.
    pub fn of(method: Method, rays: &[Ray]) -> Option<Arranged> {
        let width = match method {
            Method::Kd(KdMethod::Packet) => PACKET_WIDTH,
            m if is_wide_packet(m) => WIDE_PACKET,
            _ => return None,
        };
        let order = packet_slots_of(rays, width);
        let pad = Ray { origin: [f32::NAN; 3], tmin: 0.0, dir: [f32::NAN; 3], tmax: 0.0 };
        let arranged = order.iter().map(|&i| if i == PADDING { pad } else { rays[i as usize] }).collect();
        Some(Arranged { order, rays: arranged })
    }

    /// Puts per-slot values (`stride` each) back in ray order: `out[order[s]] = slots[s]`.
    pub fn restore<T: Copy>(&self, slots: &[T], stride: usize, out: &mut [T]) {
        for (s, &i) in self.order.iter().enumerate() {
            if i != PADDING {
                let (dst, src) = (i as usize * stride, s * stride);
                out[dst..dst + stride].copy_from_slice(&slots[src..src + stride]);
            }
        }
    }
}
