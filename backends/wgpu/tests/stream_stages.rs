//! The stream method's stages on the device against the core's serial pipeline
//! (`raytrail_core::stream::pipeline::plan` with `Serial`): keys, sorted order, packet bounds,
//! frustums (bit for bit), the traversal's final pair queue, the ranges, the queue sizes and the
//! box-test count must be identical, on generated scenes with the conformance suite's ray sets,
//! a set with untraceable rays, a set long enough for three-level scans, and parameters that
//! take the exact-key path and cut cells into many packets. Then whole traces: the report's
//! figures and counters against the serial backend's.
//!
//! Skipped with a one-line reason without an adapter, unless `RAYTRAIL_REQUIRE_GPU=1`.

mod common;

use raytrail_conformance::rays::RaySetSize;
use raytrail_conformance::reference::SerialBackend;
use raytrail_conformance::suite::{generated_scene, GENERATED_RAYS, MESH_RAYS};
use raytrail_conformance::{ray_sets, NamedScene};
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::glam::Vec3;
use raytrail_core::method::{Bvh2Method, Method, Query, StreamMethod};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::stream::pipeline::{plan, StageSeconds};
use raytrail_core::stream::ray_hash::RayGrid;
use raytrail_core::stream::{FrustumCull, Serial, StreamParams};
use raytrail_core::trace::{Record, Trace, TraceOptions};
use raytrail_core::{Hit, Ray};
use raytrail_wgpu::WgpuBackend;
use std::sync::Arc;

const STREAM: Method = Method::Stream(StreamMethod::Frustum8);

fn open() -> Option<WgpuBackend> {
    common::open_or_skip("the stream stage checks", WgpuBackend::new)
}

/// The scene prepared for the stream method (and the stack method, which makes the ray sets).
fn prepare(named: &NamedScene) -> Arc<PreparedScene> {
    let bvh = SahBuilder::default().build(named.scene.triangles()).expect("SAH build");
    Arc::new(PreparedScene::new(&named.scene, bvh, &[Method::Bvh2(Bvh2Method::Stack), STREAM]).expect("prepare"))
}

/// The suite's five ray sets for the scene, then one with untraceable rays mixed in.
fn rays_for(prepared: &Arc<PreparedScene>, named: &NamedScene) -> Vec<(String, Vec<Ray>)> {
    rays_sized(prepared, named, GENERATED_RAYS)
}

/// As [`rays_for`], at `size`.
fn rays_sized(prepared: &Arc<PreparedScene>, named: &NamedScene, size: RaySetSize) -> Vec<(String, Vec<Ray>)> {
    let serial = SerialBackend;
    let s = serial.prepare(prepared.clone()).expect("serial scene");
    let mut trace = |rays: &[Ray]| {
        let mut hits = vec![Hit::MISS; rays.len()];
        serial.trace(&s, rays, &TraceOptions::new(Bvh2Method::Stack), &mut hits).expect("trace");
        hits
    };
    let mut sets: Vec<(String, Vec<Ray>)> =
        ray_sets(&named.scene, size, &mut trace).into_iter().map(|s| (s.kind.name().to_string(), s.rays)).collect();
    let mut mixed = sets[0].1.clone();
    for (i, r) in mixed.iter_mut().enumerate() {
        match i % 7 {
            0 => r.origin[1] = f32::NAN,
            1 => r.dir = [0.0; 3],
            2 => (r.tmin, r.tmax) = (2.0, 1.0),
            3 => r.dir[2] = f32::INFINITY,
            _ => {}
        }
    }
    sets.push(("untraceable mixed in".to_string(), mixed));
    sets
}

/// Runs the GPU stages and the core's on `rays`; panics on the first array that differs.
fn check_plan(backend: &WgpuBackend, prepared: &Arc<PreparedScene>, what: &str, rays: &[Ray], params: &StreamParams) {
    let scene = backend.prepare(prepared.clone()).expect("prepare on the device");
    let s = prepared.stream_scene(StreamMethod::Frustum8).expect("stream scene");
    let expected = plan::<_, FrustumCull>(&Serial, &s, rays, params, &mut StageSeconds::default()).expect("core plan");
    let got = backend.stream_plan(&scene, rays, params).expect("device plan");
    assert_eq!(got.keys, expected.keys, "{what}: keys");
    assert_eq!(got.order, expected.order, "{what}: sorted order");
    assert_eq!(got.packets, expected.packets, "{what}: packet bounds");
    let bits = |f: &[raytrail_core::stream::Frustum]| -> Vec<u32> { bytemuck::cast_slice(f).to_vec() };
    let (g, e) = (bits(&got.frustums), bits(&expected.frustums));
    if let Some(at) = g.iter().zip(&e).position(|(a, b)| a != b) {
        panic!(
            "{what}: frustum {} differs (word {}):\n got      {:?}\n expected {:?}",
            at / 20,
            at % 20,
            got.frustums[at / 20],
            expected.frustums[at / 20]
        );
    }
    assert_eq!(g.len(), e.len(), "{what}: frustum count");
    assert_eq!(got.lists.queue_sizes, expected.lists.queue_sizes, "{what}: queue sizes");
    assert_eq!(got.lists.box_tests, expected.lists.box_tests, "{what}: box tests");
    assert_eq!(got.lists.pairs, expected.lists.pairs, "{what}: final pair queue");
    assert_eq!(got.lists.ranges, expected.lists.ranges, "{what}: ranges");
    eprintln!(
        "{what}: {} rays, {} packets, {} leaf references, queues {:?}: identical",
        rays.len(),
        expected.packet_count(),
        expected.lists.pairs.node.len(),
        expected.lists.queue_sizes
    );
}

/// Default parameters; a fine origin grid whose cell pair needs more than 32 bits, so its Morton
/// code is cut (the coarsening path); and a coarse grid that fits as it is, with packets of at most
/// three rays (cells cut into many packets).
fn params_sets(prepared: &PreparedScene) -> [StreamParams; 3] {
    let d = StreamParams::default();
    let fine = StreamParams { origin_cell_fraction: 1e-4, direction_cell_fraction: 1.0 / 64.0, ..d };
    let coarse = StreamParams { origin_cell_fraction: 0.25, direction_cell_fraction: 0.5, max_packet: 3, ..d };
    let bounds = prepared.stream_scene(StreamMethod::Frustum8).expect("stream scene").bounds;
    assert!(RayGrid::new(&bounds, &fine).origin_drop > 0, "the fine grid's origin code should be cut");
    assert_eq!(RayGrid::new(&bounds, &coarse).origin_drop, 0, "the coarse grid's pair should fit as it is");
    [d, fine, coarse]
}

fn check_scene(name: &str) {
    let Some(backend) = open() else { return };
    let named = generated_scene(name);
    let prepared = prepare(&named);
    for params in params_sets(&prepared) {
        for (set, rays) in rays_for(&prepared, &named) {
            check_plan(&backend, &prepared, &format!("{name}/{set}/{params:?}"), &rays, &params);
        }
    }
}

#[test]
fn sphereflake_stages_match_the_core() {
    check_scene("sphereflake");
}

#[test]
fn triangle_soup_stages_match_the_core() {
    check_scene("triangle_soup");
}

#[test]
fn far_from_origin_stages_match_the_core() {
    check_scene("far_from_origin");
}

/// More than 65,536 rays: every scan runs three levels deep, the radix sort's counts two.
#[test]
fn a_long_ray_set_and_an_empty_one_match_the_core() {
    let Some(backend) = open() else { return };
    let named = generated_scene("sphereflake");
    let prepared = prepare(&named);
    let sets = rays_for(&prepared, &named);
    let mut long: Vec<Ray> = Vec::new();
    let mut k = 0u32;
    while long.len() <= 70_000 {
        for (_, rays) in &sets {
            // Shifted copies: distinct keys for many, equal ones for the rest.
            let shift = (k % 5) as f32 * 0.01;
            long.extend(rays.iter().map(|r| Ray { origin: (Vec3::from(r.origin) + shift).to_array(), ..*r }));
            k += 1;
        }
    }
    check_plan(&backend, &prepared, "sphereflake/long", &long, &StreamParams::default());
    check_plan(&backend, &prepared, "sphereflake/empty", &[], &StreamParams::default());
}

/// Whole traces: hits (any hit: occluded or not), the report's figures (all but the times and the
/// working bytes, which count the CPU's gathered copy of the rays) and the rays counted, against
/// the serial backend. The leaves and triangles counted are the device's own: it visits each
/// packet's leaves in list order, the CPU by their near side with an early stop, so the work
/// differs where the answer does not.
#[test]
fn traces_report_the_cores_figures() {
    let Some(backend) = open() else { return };
    let named = generated_scene("triangle_soup");
    let prepared = prepare(&named);
    let serial = SerialBackend;
    let serial_scene = serial.prepare(prepared.clone()).expect("serial scene");
    let scene = backend.prepare(prepared.clone()).expect("device scene");
    // Leaf lists in one round, and in rounds of three leaves (each invocation going on from the
    // hit the round before stored).
    let rounds = [StreamParams::default(), StreamParams { split_leaves: 3, ..StreamParams::default() }];
    for (set, rays) in rays_for(&prepared, &named) {
        for (query, params) in [Query::Closest, Query::Any].into_iter().flat_map(|q| rounds.map(|p| (q, p))) {
            let opts = TraceOptions::new(STREAM).query(query).record(Record::Counters).stream(params);
            backend.warm_up(&scene, STREAM, &opts).expect("every stream kernel compiles");
            let (mut want, mut got) = (vec![Hit::MISS; rays.len()], vec![Hit::MISS; rays.len()]);
            let expected = serial.trace(&serial_scene, &rays, &opts, &mut want).expect("serial trace");
            let report = backend.trace(&scene, &rays, &opts, &mut got).expect("device trace");
            let same = |a: &Hit, b: &Hit| if query == Query::Closest { a.same_as(b) } else { a.is_hit() == b.is_hit() };
            assert!(want.iter().zip(&got).all(|(a, b)| same(a, b)), "{set}/{query:?}: hits differ");
            let (mut e, mut g) = (expected.stream.expect("serial figures"), report.stream.expect("device figures"));
            (e.seconds, g.seconds) = (StageSeconds::default(), StageSeconds::default());
            (e.working_bytes, g.working_bytes) = (0, 0);
            assert_eq!(g, e, "{set}/{query:?}: figures");
            let (ec, gc) = (expected.counters.expect("serial counters"), report.counters.expect("device counters"));
            assert_eq!(gc.rays, ec.rays, "{set}/{query:?}: rays counted");
            assert!(gc.leaves > 0 && gc.primitive_tests > 0, "{set}: the device's counters should count something");
            assert!(ec.leaves > 0 && ec.primitive_tests > 0, "{set}: the counters should count something");
        }
    }
}

/// A real mesh's ray sets (the adversarial set's rays run through the dragon from anywhere).
#[test]
fn the_dragons_stages_equal_the_cores() {
    let Some(backend) = open() else { return };
    let Some(named) = raytrail_conformance::suite::mesh("dragon_vrip_res2.ply.gz") else { return };
    let prepared = prepare(&named);
    for (set, rays) in rays_sized(&prepared, &named, MESH_RAYS) {
        check_plan(&backend, &prepared, &format!("dragon_res2/{set}"), &rays, &StreamParams::default());
    }
}
