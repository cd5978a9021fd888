//! A wide traversal whose sorting network lacks one compare-and-swap visits children in the wrong
//! order on some rays: the suite's comparison with the serial reference backend (scalar box tests,
//! an insertion sort) must catch it, for either width and wherever the missing exchange sits.

use raytrail_conformance::check::{check_against, Context, Difference};
use raytrail_conformance::rays::{ray_sets, RaySetSize};
use raytrail_conformance::suite::generated_scene;
use raytrail_conformance::SerialBackend;
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::intersect::Watertight;
use raytrail_core::method::{Bvh2Method, Method, WideMethod};
use raytrail_core::observe::{Both, Counters, Recorder};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{check_buffers, Record, Report, Trace, TraceOptions};
use raytrail_core::wide::network::sort_network_without;
use raytrail_core::wide::traverse::trace_wide_ray;
use raytrail_core::wide::{sort_keys, ChildHits, ChildKernel, FastKernel, WideNode, WideTree};
use raytrail_core::{Error, Hit, Ray};
use std::sync::Arc;

/// The fast kernel with a network lacking compare-and-swap `D` (none for `usize::MAX`).
struct DroppedExchange<const D: usize>;

impl<const D: usize> ChildKernel for DroppedExchange<D> {
    const BLOCKS: bool = true;

    fn test<const W: usize>(
        node: &WideNode<W>,
        slab: &raytrail_core::intersect::SlabRay,
        tmin: f32,
        tmax: f32,
    ) -> ChildHits<W> {
        FastKernel::test(node, slab, tmin, tmax)
    }
    fn order<const W: usize>(hits: &ChildHits<W>, order: &mut [u32; W]) -> usize {
        let (mut keys, mut slots) = sort_keys(hits);
        sort_network_without(&mut keys, &mut slots, D);
        *order = slots;
        hits.mask.count_ones() as usize
    }
}

/// A backend of the wide methods alone, with the faulty network.
struct Faulty<const D: usize>;

impl<const D: usize> Trace for Faulty<D> {
    type Prepared = Arc<PreparedScene>;
    fn name(&self) -> &str {
        "faulty-network"
    }
    fn supports(&self, method: Method) -> bool {
        matches!(method, Method::Wide(_))
    }
    fn prepare(&self, scene: Arc<PreparedScene>) -> Result<Self::Prepared, Error> {
        Ok(scene)
    }
    fn trace(
        &self,
        scene: &Self::Prepared,
        rays: &[Ray],
        opts: &TraceOptions,
        hits: &mut [Hit],
    ) -> Result<Report, Error> {
        check_buffers(rays, hits)?;
        let m = WideMethod::try_from(opts.method)?;
        let (root, tree) = (scene.wide_root(m)?, scene.wide_tree(m)?);
        let mut enumerations = Vec::new();
        // In the scene's frame, as every backend traces (directions of adversarial sizes are
        // scaled to unit size).
        let framed = scene.frame_rays(rays);
        for (ray, hit) in framed.rays().iter().zip(hits.iter_mut()) {
            let mut o = Both(Counters::default(), Recorder::default());
            *hit = match tree {
                WideTree::Four(t) => trace_wide_ray::<4, _, Watertight, DroppedExchange<D>, _>(
                    &t.memory(),
                    root,
                    ray,
                    opts.query,
                    &mut o,
                ),
                WideTree::Eight(t) => trace_wide_ray::<8, _, Watertight, DroppedExchange<D>, _>(
                    &t.memory(),
                    root,
                    ray,
                    opts.query,
                    &mut o,
                ),
            };
            enumerations.push(scene.canonical_ids(opts.method, o.1.nodes)?);
        }
        framed.finish(hits);
        let mut report = Report::new(rays.len(), 0.0);
        report.enumerations = (opts.record == Record::Enumerations).then_some(enumerations);
        Ok(report)
    }
}

/// Mismatches the suite's check finds with exchange `D` left out, on the triangle soup (random
/// overlapping triangles: nodes whose children all overlap, so late exchanges of the network
/// matter on many rays).
fn caught<const D: usize>(method: WideMethod) -> usize {
    let named = generated_scene("triangle_soup");
    let bvh = SahBuilder::default().build(named.scene.triangles()).expect("build");
    let prepared =
        Arc::new(PreparedScene::new(&named.scene, bvh, &[method.into(), Bvh2Method::Stack.into()]).expect("prepare"));
    let serial_scene = SerialBackend.prepare(prepared.clone()).expect("prepare");
    let mut closest = |rays: &[Ray]| {
        let mut hits = vec![Hit::MISS; rays.len()];
        SerialBackend.trace(&serial_scene, rays, &TraceOptions::new(Bvh2Method::Stack), &mut hits).expect("trace");
        hits
    };
    let sets = ray_sets(&named.scene, RaySetSize { width: 32, height: 24, uniform_count: 2048 }, &mut closest);
    let mut found = 0;
    for set in &sets {
        let ctx = Context { scene: &named.name, ray_set: set.kind.name(), backend: "faulty-network" };
        let mismatches =
            check_against(&SerialBackend, &serial_scene, &Faulty::<D>, &prepared, ctx, &set.rays, &[method.into()])
                .expect("trace");
        found += mismatches.iter().filter(|m| matches!(m.difference, Difference::Enumeration { .. })).count();
    }
    found
}

/// Every exchange of a network, each left out in turn: the checks must catch every one.
macro_rules! every_exchange_caught {
    ($method:expr; $($d:literal),*) => {
        $(assert!(caught::<$d>($method) > 0, "{} network without exchange {} passed", $method, $d);)*
    };
}

#[test]
fn every_dropped_exchange_of_either_network_is_caught() {
    every_exchange_caught!(WideMethod::BVH4; 0, 1, 2, 3, 4, 5);
    every_exchange_caught!(WideMethod::BVH8; 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23);
}

#[test]
fn the_intact_network_passes_the_same_check() {
    assert_eq!(caught::<{ usize::MAX }>(WideMethod::BVH4), 0);
    assert_eq!(caught::<{ usize::MAX }>(WideMethod::BVH8), 0);
}
