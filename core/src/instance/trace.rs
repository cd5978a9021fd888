//! Tracing an instanced scene through any backend, in waves.
//!
//! Each ray first walks the top-level BVH and lists the instances whose world box it enters, with
//! the entry distance (in `f64`, over the ray's interval), nearest first; instances its mask
//! excludes are never listed, so never entered. Then, wave after wave, every unanswered ray takes
//! the nearest instance on its list that it enters no farther than its closest hit so far; the
//! wave's rays are grouped by instance, mapped into each mesh's frame ([`Transform`]) with their
//! interval ending at their closest hit so far, and traced as one batch per instance through the
//! backend's [`Trace::trace`], with the caller's method and query. A ray is answered when its list
//! runs out, when an any-hit query finds a hit, or when a mesh refuses it.
//!
//! Batches keep every backend and method usable on instances unchanged (the GPU's included); the
//! price is a backend call per instance per wave, which many instances on few rays pay.
//!
//! [`Transform`]: super::Transform

use super::hit::InstanceHit;
use super::scene::InstancedScene;
use crate::bvh2::NodeKind;
use crate::trace::{count_untraceable, Report, Trace, TraceOptions};
use crate::{Aabb, Error, Hit, Ray};
use alloc::vec;
use alloc::vec::Vec;

/// What an instanced trace did, beyond its [`Report`].
#[derive(Clone, Debug, Default)]
pub struct InstancedReport {
    /// Rays, refusals and untraceable rays of the whole call (`seconds` is 0: the core has no
    /// clock; the backends' calls are summed in `backend_seconds`).
    pub report: Report,
    /// Seconds of the backend's trace calls, summed.
    pub backend_seconds: f64,
    /// Waves traced.
    pub waves: usize,
    /// Per instance (in the scene's order), how many rays were traced into it.
    pub entered: Vec<u64>,
}

/// Traces `rays` through `scene` with `backend` into `hits` (same length), by
/// `options.method` and `options.query`; `masks`, where given, holds one mask per ray (see
/// [`Instance::mask`](super::Instance::mask)), and without them every ray has every bit set.
///
/// Closest hits tie as a flat scene's do, extended to instances: at equal `t` the instance
/// listed first wins, then the smaller primitive id. Errors: [`Error::BufferMismatch`] where
/// `hits` or `masks` differ in length from `rays`, and any error of the backend.
pub fn trace_instanced<B: Trace>(
    backend: &B,
    scene: &InstancedScene<B::Prepared>,
    rays: &[Ray],
    masks: Option<&[u32]>,
    options: &TraceOptions,
    hits: &mut [InstanceHit],
) -> Result<InstancedReport, Error> {
    if hits.len() != rays.len() {
        return Err(Error::BufferMismatch { rays: rays.len(), hits: hits.len() });
    }
    if let Some(m) = masks {
        if m.len() != rays.len() {
            return Err(Error::BufferMismatch { rays: rays.len(), hits: m.len() });
        }
    }
    hits.fill(InstanceHit::MISS);
    let any = options.query.is_any();
    let lists = Candidates::new(scene, rays, masks);
    let mut next: Vec<u32> = lists.start.clone();
    let mut done = vec![false; rays.len()];
    let mut out = InstancedReport { entered: vec![0; scene.instances().len()], ..Default::default() };
    out.report.rays = rays.len();
    out.report.untraceable = count_untraceable(rays);
    let bottom = TraceOptions { record: crate::trace::Record::Nothing, ..*options };
    let mut by_instance: Vec<Vec<u32>> = vec![Vec::new(); scene.instances().len()];
    let (mut mapped, mut got) = (Vec::new(), Vec::new());
    loop {
        // Each unanswered ray's next instance that may still hold a closer hit.
        let mut any_taken = false;
        for (r, ray) in rays.iter().enumerate() {
            if done[r] {
                continue;
            }
            let limit = if hits[r].is_hit() { hits[r].t } else { ray.tmax };
            let end = lists.start[r + 1];
            while next[r] < end && lists.t_enter[next[r] as usize] > f64::from(limit) {
                next[r] += 1;
            }
            if next[r] == end {
                done[r] = true;
                continue;
            }
            by_instance[lists.instance[next[r] as usize] as usize].push(r as u32);
            next[r] += 1;
            any_taken = true;
        }
        if !any_taken {
            break;
        }
        out.waves += 1;
        for (inst, wave) in by_instance.iter_mut().enumerate() {
            if wave.is_empty() {
                continue;
            }
            let to_object = &scene.to_object[inst];
            mapped.clear();
            mapped.extend(wave.iter().map(|&r| {
                let (ray, best) = (&rays[r as usize], &hits[r as usize]);
                let mut m = to_object.ray(ray);
                if best.is_hit() {
                    m.tmax = best.t;
                }
                m
            }));
            got.clear();
            got.resize(wave.len(), Hit::MISS);
            let mesh = &scene.meshes()[scene.instances()[inst].mesh as usize];
            let report = backend.trace(mesh, &mapped, &bottom, &mut got)?;
            out.backend_seconds += report.seconds;
            out.entered[inst] += wave.len() as u64;
            for ((&r, h), m) in wave.iter().zip(&got).zip(&mapped) {
                let r = r as usize;
                if h.is_refused() || (!m.is_traceable() && rays[r].is_traceable()) {
                    // The mesh cannot answer the mapped ray (or mapping it left the float
                    // range): the whole ray is refused, never answered as a miss.
                    hits[r] = InstanceHit::REFUSED;
                    done[r] = true;
                    out.report.refused += 1;
                } else if h.is_hit() && hits[r].is_beaten_by(h, inst as u32) {
                    hits[r] = InstanceHit::from_hit(h, inst as u32, scene.instances()[inst].id);
                    done[r] |= any;
                }
            }
            wave.clear();
        }
    }
    Ok(out)
}

/// Per ray, the instances whose world box it enters, nearest first, as one flat list: ray `r`'s
/// entries are `start[r]..start[r + 1]`.
struct Candidates {
    start: Vec<u32>,
    instance: Vec<u32>,
    t_enter: Vec<f64>,
}

impl Candidates {
    fn new<P>(scene: &InstancedScene<P>, rays: &[Ray], masks: Option<&[u32]>) -> Self {
        let mut c = Candidates { start: Vec::with_capacity(rays.len() + 1), instance: Vec::new(), t_enter: Vec::new() };
        let nodes = scene.top.nodes();
        let order = scene.top.prim_order();
        let mut stack: Vec<u32> = Vec::new();
        let mut found: Vec<(f64, u32)> = Vec::new();
        for (r, ray) in rays.iter().enumerate() {
            c.start.push(c.instance.len() as u32);
            if !ray.is_traceable() {
                continue;
            }
            let mask = masks.map_or(u32::MAX, |m| m[r]);
            let slab = Slab::new(ray);
            found.clear();
            stack.clear();
            stack.push(0);
            while let Some(n) = stack.pop() {
                let node = &nodes[n as usize];
                let Some(t_node) = slab.entry(&node.bounds) else { continue };
                match node.kind {
                    NodeKind::Internal { left, right } => {
                        stack.push(right);
                        stack.push(left);
                    }
                    NodeKind::Leaf { first, count } => {
                        for &inst in &order[first as usize..(first + count) as usize] {
                            if scene.instances()[inst as usize].mask & mask == 0 {
                                continue;
                            }
                            // A leaf of one instance has that instance's box: its entry is known.
                            let t =
                                if count == 1 { Some(t_node) } else { slab.entry(&scene.world_boxes[inst as usize]) };
                            if let Some(t) = t {
                                found.push((t, inst));
                            }
                        }
                    }
                }
            }
            // Nearest first; at equal entry the instance listed first (a fixed order).
            found.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for &(t, inst) in &found {
                c.instance.push(inst);
                c.t_enter.push(t);
            }
        }
        c.start.push(c.instance.len() as u32);
        c
    }
}

/// A ray in `f64` for the slab test: its origin, the reciprocal of each non-zero direction
/// component, and its interval.
struct Slab {
    origin: [f64; 3],
    /// `1 / d` per axis; `None` where `d == 0` (the ray is parallel to that axis's slabs).
    inv: [Option<f64>; 3],
    tmin: f64,
    tmax: f64,
}

impl Slab {
    fn new(ray: &Ray) -> Self {
        let d = ray.dir.map(f64::from);
        Slab {
            origin: ray.origin.map(f64::from),
            inv: d.map(|d| (d != 0.0).then(|| 1.0 / d)),
            tmin: f64::from(ray.tmin),
            tmax: f64::from(ray.tmax),
        }
    }

    /// Where the ray enters `b` over its interval, or `None` where it misses: the slab test in
    /// `f64` (each slab distance off the exact one by two roundings at most).
    fn entry(&self, b: &Aabb) -> Option<f64> {
        let (mut lo, mut hi) = (self.tmin, self.tmax);
        for i in 0..3 {
            let o = self.origin[i];
            let (bl, bh) = (f64::from(b.min[i]), f64::from(b.max[i]));
            let Some(inv) = self.inv[i] else {
                if o < bl || o > bh {
                    return None;
                }
                continue;
            };
            let (a, c) = ((bl - o) * inv, (bh - o) * inv);
            lo = lo.max(a.min(c));
            hi = hi.min(a.max(c));
        }
        // A margin of 2^-40 relative: the roundings above, generously.
        (lo <= hi + hi.abs() / 1_099_511_627_776.0).then_some(lo)
    }
}
