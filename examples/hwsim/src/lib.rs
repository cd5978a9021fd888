//! raytrail-hwsim: a lockstep (SIMT) simulator over raytrail's traversal state machines, for
//! prototyping traversal hardware.
//!
//! Rays are grouped in warps of `W` lanes (default 32). In each cycle every lane whose traversal
//! has not ended makes exactly one [`Machine::step`](raytrail_core::traverse::Machine::step) of the
//! core's own state machine (the code the CPU backend runs) of any structure: the BVH2 methods, the
//! kd methods but kd-packet, and the wide BVHs but the packet and ray-list methods (bvh8-packet,
//! bvh8-lists and their `-sah` twins, whose rays share walks), the stackless bvh4-hash included.
//! The simulator records how many lanes were active, what each transition
//! was (internal node, leaf, backtracking step served by a stack pop, the register, the hash, a
//! walk over links or a restart) and what it read, through [`CountingMemory`], [`CountingKdMemory`] or
//! [`CountingWideMemory`]. From that it reports SIMT efficiency, cycles per warp, memory traffic per
//! table, distinct cache lines per warp-step and per ray, per-ray state, stack traffic and the
//! chains of dependent reads. The ray stream of Garanzha & Loop 2010 is no state machine per ray: its
//! intersection stage is modelled by [`stream_lanes`], warps of a packet's rays stepping through
//! the packet's leaf list together.
//!
//! - [`simulate`] runs one method over a batch of rays; [`report::tables`] prints a comparison.
//! - [`Scenario`] builds the tree, the tables and a ray set for a scene.
#![warn(missing_docs)]

mod bvh2_lanes;
mod kd_lanes;
pub mod memory;
pub mod report;
pub mod sim;
pub mod start;
mod stepper;
pub mod stream_lanes;
mod trail_lanes;
mod wide_lanes;

pub use memory::{CountingKdMemory, CountingMemory, CountingWideMemory, ReadTally, Table, Traffic};
pub use sim::{simulate, CycleRecord, MethodReport, MethodRun, SimConfig, Transition};

use raytrail_conformance::rays::{default_light, diffuse, primary, scene_epsilon, shadow, RAY_SEED};
use raytrail_core::bvh2::traverse::trace_ray;
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::intersect::Watertight;
use raytrail_core::key::KeyWidth;
use raytrail_core::method::{Bvh2Method, Method, Query};
use raytrail_core::observe::NoObserver;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::scene::Scene;
use raytrail_core::{Hit, Ray};

/// The ray sets the simulator can make.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// Camera rays in Morton order (closest hit): coherent.
    Primary,
    /// Rays from the primary hits to a point light (any hit).
    Shadow,
    /// Cosine-weighted bounces from the primary hits (closest hit): incoherent.
    Diffuse,
}

impl RayKind {
    /// The kind of a command-line name.
    pub fn from_name(name: &str) -> Option<RayKind> {
        match name {
            "primary" => Some(RayKind::Primary),
            "shadow" => Some(RayKind::Shadow),
            "diffuse" => Some(RayKind::Diffuse),
            _ => None,
        }
    }

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Primary => "primary",
            RayKind::Shadow => "shadow",
            RayKind::Diffuse => "diffuse",
        }
    }

    /// The query the set is meant for: any hit for shadow rays, closest hit otherwise.
    pub fn query(self) -> Query {
        if self == RayKind::Shadow {
            Query::Any
        } else {
            Query::Closest
        }
    }
}

/// A scene prepared for every method, with a ray set.
#[derive(Clone, Debug)]
pub struct Scenario {
    /// The scene.
    pub scene: Scene,
    /// Tree, layouts and hash tables for every method.
    pub prepared: PreparedScene,
    /// The rays, in the order they are grouped into warps.
    pub rays: Vec<Ray>,
    /// What the rays are.
    pub kind: RayKind,
}

impl Scenario {
    /// Builds the SAH tree of `scene`, prepares it for every method ([`Method::ALL`]: the BVH2
    /// layouts and hashes, the kd-tree, the wide trees) and makes `kind` rays from a
    /// `width` x `height` camera framing the scene (shadow and diffuse rays start at its hits).
    pub fn new(scene: Scene, kind: RayKind, width: u32, height: u32) -> Result<Scenario, raytrail_core::Error> {
        let bvh = SahBuilder::default().build(scene.triangles())?;
        let prepared = PreparedScene::new(&scene, bvh, &Method::ALL)?;
        let camera = primary(&scene, width, height);
        let rays = match kind {
            RayKind::Primary => camera,
            RayKind::Shadow | RayKind::Diffuse => {
                let hits = reference_hits(&prepared, &camera, Query::Closest)?;
                let bounds = scene.bounds();
                if kind == RayKind::Shadow {
                    shadow(&camera, &hits, default_light(bounds), scene_epsilon(bounds))
                } else {
                    diffuse(&camera, &hits, &scene, RAY_SEED)
                }
            }
        };
        Ok(Scenario { scene, prepared, rays, kind })
    }
}

/// Hits of `rays` with the stack method through `trace_ray`, one ray after another (no lockstep):
/// the reference the simulator must reproduce.
pub fn reference_hits(prepared: &PreparedScene, rays: &[Ray], query: Query) -> Result<Vec<Hit>, raytrail_core::Error> {
    let (mem, root) = (prepared.memory(Bvh2Method::Stack)?, prepared.root(Bvh2Method::Stack)?);
    Ok(match prepared.key_width() {
        KeyWidth::W32 => rays
            .iter()
            .map(|r| trace_ray::<u32, _, Watertight, _>(Bvh2Method::Stack, &mem, root, r, query, &mut NoObserver))
            .collect(),
        KeyWidth::W64 => rays
            .iter()
            .map(|r| trace_ray::<u64, _, Watertight, _>(Bvh2Method::Stack, &mem, root, r, query, &mut NoObserver))
            .collect(),
    })
}
