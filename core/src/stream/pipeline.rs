//! The four stages end to end (Garanzha & Loop 2010, Fig. 1): sort the rays into packets, build a
//! frustum per packet, traverse the tree breadth-first with the frustums, intersect each packet's
//! rays with its leaves. Written once over [`Parallel`], so the serial reference and a parallel
//! backend run the same code and produce the same arrays.

use super::exec::Parallel;
use super::frustum::{Frustum, FrustumTest, NO_AXIS};
use super::levels::LevelBvh;
use super::localized::intersect_packet;
use super::ray_hash::RayGrid;
use super::sort::{compress, decompress, packets};
use super::traverse::{traverse, LeafLists};
use super::StreamParams;
use crate::intersect::{MollerTrumbore, TriangleTest, Watertight};
use crate::method::Query;
use crate::observe::{Counters, NoObserver, Observer};
use crate::prepared::seconds_since;
use crate::trace::{Record, TraceOptions, TriangleTestKind};
use crate::wide::ChildKernel;
use crate::{Aabb, Error, Hit, Ray};
use alloc::vec;
use alloc::vec::Vec;

/// Seconds per stage (zero without the `std` feature's clock).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageSeconds {
    /// Hashing, sorting and packet decomposition.
    pub sort: f64,
    /// Frustum creation.
    pub frustums: f64,
    /// Breadth-first traversal.
    pub traversal: f64,
    /// Localized intersection, and the hits put back in ray order.
    pub intersection: f64,
}

/// What a stream trace did: the paper's working figures (its Table 1) and stage times.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StreamStats {
    /// Packets (frustums).
    pub packets: usize,
    /// Frustums with at least one ray that can hit anything.
    pub active_frustums: usize,
    /// Traversal queue length at the start of each level, then the final (leaf) queue's.
    pub queue_sizes: Vec<u32>,
    /// Leaf references over all frustums (the paper's LS; `packets` is its FS).
    pub leaf_refs: usize,
    /// The longest leaf list of one frustum (the paper's bad case is one frustum holding most
    /// leaf references).
    pub largest_list: usize,
    /// Frustum-box tests.
    pub box_tests: u64,
    /// Peak bytes of the working arrays (keys, order, the rays gathered in sorted order, packet
    /// bounds, frustums, two queues).
    pub working_bytes: usize,
    /// Time per stage.
    pub seconds: StageSeconds,
}

/// The first three stages' output: everything intersection needs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StreamPlan {
    /// Each ray's key.
    pub keys: Vec<u32>,
    /// The rays in sorted order (indices).
    pub order: Vec<u32>,
    /// The rays themselves in sorted order: gathered once, so that the frustum and intersection
    /// stages read each packet's rays from consecutive memory.
    pub sorted_rays: Vec<Ray>,
    /// Packet bounds in `order`: packet `p` is `bounds[p]..bounds[p + 1]`.
    pub packets: Vec<u32>,
    /// One frustum per packet.
    pub frustums: Vec<Frustum>,
    /// Each frustum's leaves.
    pub lists: LeafLists,
}

impl StreamPlan {
    /// Number of packets.
    pub fn packet_count(&self) -> usize {
        self.packets.len().saturating_sub(1)
    }

    /// The ray indices of packet `p` (empty for a packet that does not exist).
    pub fn packet(&self, p: usize) -> &[u32] {
        self.packet_range(p).and_then(|r| self.order.get(r)).unwrap_or(&[])
    }

    /// The rays of packet `p`, in sorted order (empty for a packet that does not exist).
    pub fn packet_rays(&self, p: usize) -> &[Ray] {
        self.packet_range(p).and_then(|r| self.sorted_rays.get(r)).unwrap_or(&[])
    }

    /// The leaves (node indices) packet `p`'s frustum reached, in order (empty for a packet that
    /// does not exist).
    pub fn leaves(&self, p: usize) -> &[u32] {
        let Some(&[start, len]) = self.lists.ranges.get(p) else { return &[] };
        self.lists.pairs.node.get(start as usize..(start as usize).saturating_add(len as usize)).unwrap_or(&[])
    }

    fn packet_range(&self, p: usize) -> Option<core::ops::Range<usize>> {
        Some(*self.packets.get(p)? as usize..*self.packets.get(p + 1)? as usize)
    }
}

/// The scene a stream trace runs over: the level-order tree, the scene box and its largest
/// coordinate magnitude (the slack of the depth-first methods is made from it).
#[derive(Clone, Copy, Debug)]
pub struct StreamScene<'a> {
    /// The tree.
    pub tree: &'a LevelBvh,
    /// The scene box.
    pub bounds: Aabb,
    /// Its largest coordinate magnitude.
    pub scene_scale: f32,
}

/// Stages one to three: keys, the sort, packets, frustums, the breadth-first traversal.
pub fn plan<P: Parallel, F: FrustumTest>(
    exec: &P,
    scene: &StreamScene<'_>,
    rays: &[Ray],
    params: &StreamParams,
    seconds: &mut StageSeconds,
) -> Result<StreamPlan, Error> {
    params.check()?;
    let t0 = seconds_since(None);
    let grid = RayGrid::new(&scene.bounds, params);
    let keys = exec.map(rays.len(), |i| grid.key(&rays[i]));
    let mut chunks = compress(&keys);
    exec.sort_chunks(&mut chunks);
    let order = decompress(&chunks, keys.len());
    let sorted = exec.map(order.len(), |i| keys[order[i] as usize]);
    let bounds = packets(&sorted, params.max_packet);
    let sorted_rays = exec.map(order.len(), |i| rays[order[i] as usize]);
    seconds.sort = seconds_since(Some(t0));
    let t1 = seconds_since(None);
    let frustums = exec.map(bounds.len().saturating_sub(1), |p| {
        let packet = &sorted_rays[bounds[p] as usize..bounds[p + 1] as usize];
        Frustum::build(packet.iter(), &scene.bounds, scene.scene_scale)
    });
    seconds.frustums = seconds_since(Some(t1));
    let t2 = seconds_since(None);
    let lists = traverse::<P, F>(exec, scene.tree.nodes(), &frustums);
    seconds.traversal = seconds_since(Some(t2));
    Ok(StreamPlan { keys, order, sorted_rays, packets: bounds, frustums, lists })
}

/// What [`trace_stream`] returns besides the hits.
#[derive(Clone, Debug, Default)]
pub struct StreamOutput {
    /// Working figures and stage times.
    pub stats: StreamStats,
    /// Work counters of the intersection stage (when asked for).
    pub counters: Option<Counters>,
    /// Per ray: its packet, then the canonical ids of the packet's leaves in order (when asked
    /// for). This is the method's enumeration: it pins down the sort, the packets and the
    /// traversal, and the hits pin down the intersection.
    pub enumerations: Option<Vec<Vec<u32>>>,
}

/// Traces `rays` into `hits` (same length) with the stream method; `count` and `enumerate` say
/// what to record.
#[allow(clippy::too_many_arguments)]
pub fn trace_stream<P: Parallel, F: FrustumTest, T: TriangleTest, K: ChildKernel>(
    exec: &P,
    scene: &StreamScene<'_>,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    params: &StreamParams,
    count: bool,
    enumerate: bool,
) -> Result<StreamOutput, Error> {
    crate::trace::check_buffers(rays, hits)?;
    let mut seconds = StageSeconds::default();
    let plan = plan::<P, F>(exec, scene, rays, params, &mut seconds)?;
    let t3 = seconds_since(None);
    let split = params.split_leaves as usize;
    let counters = if count {
        Some(intersect_all::<P, T, K, Counters>(exec, scene, &plan, query, split, hits))
    } else {
        intersect_all::<P, T, K, NoObserver>(exec, scene, &plan, query, split, hits);
        None
    };
    seconds.intersection = seconds_since(Some(t3));
    let enumerations = enumerate.then(|| {
        let mut out = vec![Vec::new(); rays.len()];
        for p in 0..plan.packet_count() {
            let mut list = vec![p as u32];
            list.extend(plan.leaves(p).iter().map(|&l| scene.tree.canonical_id(l)));
            for &i in plan.packet(p) {
                out[i as usize] = list.clone();
            }
        }
        out
    });
    let lists = &plan.lists;
    let biggest_queue = lists.queue_sizes.iter().copied().max().unwrap_or(0) as usize;
    let stats = StreamStats {
        packets: plan.packet_count(),
        active_frustums: plan.frustums.iter().filter(|f| f.active > 0).count(),
        queue_sizes: lists.queue_sizes.clone(),
        leaf_refs: lists.pairs.node.len(),
        largest_list: lists.ranges.iter().map(|r| r[1] as usize).max().unwrap_or(0),
        box_tests: lists.box_tests,
        working_bytes: 4 * (2 * rays.len() + plan.packets.len())
            + plan.sorted_rays.len() * core::mem::size_of::<Ray>()
            + plan.frustums.len() * core::mem::size_of::<Frustum>()
            + 2 * 8 * biggest_queue,
        seconds,
    };
    Ok(StreamOutput { stats, counters, enumerations })
}

/// [`trace_stream`] with the triangle test `options` name, its query and stream parameters;
/// counts when `options` records anything, enumerates when it records enumerations (`count`
/// forces counting, as the serial reference always does).
pub fn trace_stream_with<P: Parallel, F: FrustumTest, K: ChildKernel>(
    exec: &P,
    scene: &StreamScene<'_>,
    rays: &[Ray],
    hits: &mut [Hit],
    options: &TraceOptions,
    count: bool,
) -> Result<StreamOutput, Error> {
    let count = count || options.record != Record::Nothing;
    let enumerate = options.record == Record::Enumerations;
    let (query, params) = (options.query, &options.stream);
    match options.triangle_test {
        TriangleTestKind::Watertight => {
            trace_stream::<P, F, Watertight, K>(exec, scene, rays, hits, query, params, count, enumerate)
        }
        TriangleTestKind::MollerTrumbore => {
            trace_stream::<P, F, MollerTrumbore, K>(exec, scene, rays, hits, query, params, count, enumerate)
        }
    }
}

/// Stage four over every packet, the hits put back in ray order; the observers' sum.
///
/// A leaf list longer than `split` is intersected in pieces of `split` leaves, in parallel, and
/// each ray's results merged by the closest-hit rule: the paper's remedy (Sec. 5.5) for a frustum
/// that captures most of the scene's leaves, which would otherwise leave one worker with most of
/// the stage. The answer is the same: the closest hit does not depend on the order or grouping in
/// which candidates are offered.
fn intersect_all<P: Parallel, T: TriangleTest, K: ChildKernel, O: Observer + Default + Send + Summed>(
    exec: &P,
    scene: &StreamScene<'_>,
    plan: &StreamPlan,
    query: Query,
    split: usize,
    hits: &mut [Hit],
) -> O {
    let pieces: Vec<(usize, usize, usize)> = (0..plan.packet_count())
        .flat_map(|p| {
            let n = plan.leaves(p).len();
            let count = n.div_ceil(split).max(1);
            (0..count).map(move |k| (p, k * split, ((k + 1) * split).min(n)))
        })
        .collect();
    let results = exec.map(pieces.len(), |k| {
        let (p, from, to) = pieces[k];
        let packet = plan.packet_rays(p);
        let mut out = vec![Hit::MISS; packet.len()];
        let mut obs = O::default();
        let f = &plan.frustums[p];
        let axis = (f.axis != NO_AXIS).then(|| (f.axis as usize, f.dir_signs >> f.axis & 1 == 1));
        intersect_packet::<T, K, O>(
            scene.tree,
            &plan.leaves(p)[from..to],
            axis,
            packet,
            scene.scene_scale,
            query,
            &mut out,
            &mut obs,
        );
        (out, obs)
    });
    let mut total = O::default();
    for (&(p, from, _), (piece_hits, obs)) in pieces.iter().zip(results) {
        for (&i, h) in plan.packet(p).iter().zip(piece_hits) {
            let slot = &mut hits[i as usize];
            // The first piece sets the hit; later ones offer theirs by the closest-hit rule.
            if from == 0 || (h.is_hit() && (!slot.is_hit() || slot.is_beaten_by(h.t, h.prim))) {
                *slot = h;
            }
        }
        total.add_from(&obs);
    }
    total
}

/// Observers whose per-packet values add up.
pub trait Summed {
    /// Adds `other` to `self`.
    fn add_from(&mut self, other: &Self);
}

impl Summed for Counters {
    fn add_from(&mut self, other: &Self) {
        self.add(other);
    }
}

impl Summed for NoObserver {
    fn add_from(&mut self, _: &Self) {}
}
