//! The stream method (Garanzha & Loop 2010) on the lockstep model: each packet's rays in warps
//! (the paper's "ray warps", Sec. 3.4), every lane of a warp stepping through its packet's leaf
//! list together, as the kernel of Fig. 10 does: a leaf box test per step for every lane, and the
//! leaf's triangles for the lanes whose box test passed. SIMT efficiency is the share of a warp's
//! lanes that work on a leaf's triangles when any of them does (the box tests keep every lane of
//! the warp busy; a packet smaller than a warp leaves lanes idle throughout). The same rays packed in input order (no sorting) show what the
//! sort buys: the paper's claim that sorted packets keep lanes active.

use raytrail_core::bvh2::NodeRef;
use raytrail_core::intersect::Watertight;
use raytrail_core::method::{Query, StreamMethod};
use raytrail_core::observe::{Both, Counters, Recorder};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::stream::frustum::NO_AXIS;
use raytrail_core::stream::localized::{intersect_packet, visiting_order};
use raytrail_core::stream::pipeline::plan;
use raytrail_core::stream::traverse::traverse;
use raytrail_core::stream::{Frustum, FrustumCull, LevelNode, Serial, StageSeconds, StreamParams};
use raytrail_core::wide::ReferenceKernel;
use raytrail_core::{Error, Hit, Ray};
use std::collections::HashMap;

/// How rays are grouped into packets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Packing {
    /// The method's own: hashed and sorted, cut at key changes and the packet size.
    Sorted,
    /// Runs of the packet size in the order the rays come (no sort): the baseline.
    InputOrder,
}

impl Packing {
    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Packing::Sorted => "sorted",
            Packing::InputOrder => "input order",
        }
    }
}

/// The stream method's figures on the model.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StreamReport {
    /// Rays.
    pub rays: usize,
    /// Packets (frustums).
    pub packets: usize,
    /// Warps of at most `warp` rays.
    pub warps: usize,
    /// Lanes per warp.
    pub warp: usize,
    /// Leaf steps over all warps (each warp steps through its packet's whole list).
    pub leaf_steps: u64,
    /// Leaf steps in which at least one lane entered the leaf (the warp tests triangles).
    pub triangle_steps: u64,
    /// Lane-steps that entered the leaf (did triangle work).
    pub active_lane_steps: u64,
    /// Frustum-box tests of the breadth-first traversal.
    pub frustum_box_tests: u64,
    /// Ray-triangle tests.
    pub triangle_tests: u64,
    /// Bytes read per ray: each warp reads each leaf node of its list once (32 B) and the
    /// triangles of the leaves any of its lanes entered (36 B each).
    pub bytes: u64,
}

impl StreamReport {
    /// Share of the lanes working in the warp's triangle steps.
    pub fn simt_efficiency(&self) -> f64 {
        self.active_lane_steps as f64 / (self.triangle_steps as f64 * self.warp as f64).max(1.0)
    }

    /// Lane-steps per ray: what a ray costs the machine, idle lanes included.
    pub fn lane_steps_per_ray(&self) -> f64 {
        (self.leaf_steps * self.warp as u64) as f64 / self.rays.max(1) as f64
    }

    /// Rays per warp.
    pub fn rays_per_warp(&self) -> f64 {
        self.rays as f64 / self.warps.max(1) as f64
    }

    /// Leaf steps per warp.
    pub fn steps_per_warp(&self) -> f64 {
        self.leaf_steps as f64 / self.warps.max(1) as f64
    }

    /// `x` per ray.
    pub fn per_ray(&self, x: u64) -> f64 {
        x as f64 / self.rays.max(1) as f64
    }
}

/// Runs the stream method's stages on `rays` with `packing`, then the intersection stage on the
/// lockstep model with `warp` lanes; returns the figures and every ray's hit (in ray order).
pub fn simulate_stream(
    prepared: &PreparedScene,
    rays: &[Ray],
    query: Query,
    warp: usize,
    packing: Packing,
) -> Result<(StreamReport, Vec<Hit>), Error> {
    let scene = prepared.stream_scene(StreamMethod::Frustum8)?;
    let params = StreamParams::default();
    let warp = warp.max(1);
    let (order, bounds, frustums, lists) = match packing {
        Packing::Sorted => {
            let p = plan::<_, FrustumCull>(&Serial, &scene, rays, &params, &mut StageSeconds::default())?;
            (p.order, p.packets, p.frustums, p.lists)
        }
        Packing::InputOrder => {
            let order: Vec<u32> = (0..rays.len() as u32).collect();
            let mut bounds: Vec<u32> = (0..rays.len()).step_by(params.max_packet as usize).map(|b| b as u32).collect();
            bounds.push(rays.len() as u32);
            let frustums: Vec<Frustum> = bounds
                .windows(2)
                .map(|w| Frustum::build(rays[w[0] as usize..w[1] as usize].iter(), &scene.bounds, scene.scene_scale))
                .collect();
            let lists = traverse::<_, FrustumCull>(&Serial, scene.tree.nodes(), &frustums);
            (order, bounds, frustums, lists)
        }
    };
    let nodes: &[LevelNode] = scene.tree.nodes();
    let mut report = StreamReport {
        rays: rays.len(),
        packets: bounds.len() - 1,
        warp,
        frustum_box_tests: lists.box_tests,
        ..StreamReport::default()
    };
    let mut hits = vec![Hit::MISS; rays.len()];
    for p in 0..bounds.len() - 1 {
        let [start, len] = lists.ranges[p];
        let leaves = &lists.pairs.node[start as usize..(start + len) as usize];
        let f = &frustums[p];
        let axis = (f.axis != NO_AXIS).then(|| (f.axis as usize, f.dir_signs >> f.axis & 1 == 1));
        let visit = visiting_order(scene.tree, leaves, axis);
        // A leaf's step by the reference an observer records for it.
        let step: HashMap<NodeRef, usize> =
            visit.iter().enumerate().map(|(k, &leaf)| (scene.tree.node_ref(leaf), k)).collect();
        let ids = &order[bounds[p] as usize..bounds[p + 1] as usize];
        for lanes in ids.chunks(warp) {
            report.warps += 1;
            report.leaf_steps += visit.len() as u64;
            let mut entered_by_any = vec![false; visit.len()];
            for &id in lanes {
                let ray = &rays[id as usize];
                let mut obs = Both(Counters::default(), Recorder::default());
                let mut hit = [Hit::MISS];
                intersect_packet::<Watertight, ReferenceKernel, _>(
                    scene.tree,
                    leaves,
                    axis,
                    std::slice::from_ref(ray),
                    scene.scene_scale,
                    query,
                    &mut hit,
                    &mut obs,
                );
                hits[id as usize] = hit[0];
                report.triangle_tests += obs.0.primitive_tests;
                for r in &obs.1.nodes {
                    if let Some(&k) = step.get(r) {
                        report.active_lane_steps += 1;
                        entered_by_any[k] = true;
                    }
                }
            }
            report.bytes += 32 * visit.len() as u64;
            for (k, _) in entered_by_any.iter().enumerate().filter(|(_, &e)| e) {
                report.triangle_steps += 1;
                report.bytes += 36 * u64::from(nodes[visit[k] as usize].triangles());
            }
        }
    }
    Ok((report, hits))
}

/// The table of [`StreamReport`]s, one row per packing.
pub fn table(rows: &[(Packing, StreamReport)]) -> String {
    let mut s = format!(
        "{:<12} {:>8} {:>7} {:>9} {:>11} {:>15} {:>10} {:>9} {:>14} {:>10} {:>9}\n",
        "packing",
        "packets",
        "warps",
        "rays/warp",
        "steps/warp",
        "lane-steps/ray",
        "tri steps",
        "SIMT eff",
        "frustum tests",
        "tests/ray",
        "B/ray"
    );
    for (packing, r) in rows {
        s += &format!(
            "{:<12} {:>8} {:>7} {:>9.1} {:>11.1} {:>15.1} {:>10.1} {:>8.1}% {:>14} {:>10.2} {:>9.0}\n",
            packing.name(),
            r.packets,
            r.warps,
            r.rays_per_warp(),
            r.steps_per_warp(),
            r.lane_steps_per_ray(),
            r.triangle_steps as f64 / r.warps.max(1) as f64,
            100.0 * r.simt_efficiency(),
            r.frustum_box_tests,
            r.per_ray(r.triangle_tests),
            r.per_ray(r.bytes)
        );
    }
    s
}
