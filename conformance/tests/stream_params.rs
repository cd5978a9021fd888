//! The stream method conforms at every parameter setting, not only the defaults: packets of one
//! ray and of thousands, origin cells from a millionth of the scene to all of it, direction cells
//! from a whole cube face to a thousandth, leaf lists intersected whole or in pieces of one leaf. Hits equal the stack method's bit for bit (any hit:
//! the same occlusion), the CPU backend's enumerations equal the serial reference's, and every
//! packet's leaf list holds the leaf of each of its rays' closest hits.

use raytrail_conformance::check::{check_complete, Context, PrimLeaves};
use raytrail_conformance::rays::{ray_sets, RaySetSize};
use raytrail_conformance::suite::generated_scene;
use raytrail_conformance::SerialBackend;
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::method::{Bvh2Method, Method, Query, StreamMethod};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::stream::StreamParams;
use raytrail_core::trace::{Record, Trace, TraceOptions};
use raytrail_core::{Hit, Ray};
use raytrail_cpu::CpuBackend;
use std::sync::Arc;

const STREAM: Method = Method::Stream(StreamMethod::Frustum8);

/// A backend's trace: fills the hits, returns the enumerations when recorded.
type Tracer<'a> = &'a dyn Fn(&[Ray], &TraceOptions, &mut [Hit]) -> Option<Vec<Vec<u32>>>;

fn settings() -> Vec<StreamParams> {
    let d = StreamParams::default();
    vec![
        StreamParams { max_packet: 1, ..d },
        StreamParams { split_leaves: 3, ..d },
        StreamParams { split_leaves: 1, max_packet: 1024, origin_cell_fraction: 0.5, ..d },
        StreamParams { max_packet: 7, origin_cell_fraction: 1e-6, ..d },
        StreamParams { max_packet: 4096, origin_cell_fraction: 1.0, direction_cell_fraction: 1.0, ..d },
        StreamParams { direction_cell_fraction: 1.0 / 1024.0, ..d },
        StreamParams { origin_cell_fraction: 0.05, direction_cell_fraction: 0.5, max_packet: 64, ..d },
    ]
}

fn check(scene_name: &str) {
    let named = generated_scene(scene_name);
    let bvh = SahBuilder::default().build(named.scene.triangles()).expect("build");
    let prepared =
        Arc::new(PreparedScene::new(&named.scene, bvh, &[STREAM, Bvh2Method::Stack.into()]).expect("prepare"));
    let serial_scene = SerialBackend.prepare(prepared.clone()).expect("prepare");
    let cpu = CpuBackend::new();
    let cpu_scene = cpu.prepare(prepared.clone()).expect("prepare");
    let trace = |b: Tracer<'_>, rays: &[Ray], o: TraceOptions| {
        let mut hits = vec![Hit::MISS; rays.len()];
        let e = b(rays, &o, &mut hits);
        (hits, e)
    };
    let serial = |rays: &[Ray], o: &TraceOptions, h: &mut [Hit]| {
        SerialBackend.trace(&serial_scene, rays, o, h).expect("serial trace").enumerations
    };
    let on_cpu = |rays: &[Ray], o: &TraceOptions, h: &mut [Hit]| {
        cpu.trace(&cpu_scene, rays, o, h).expect("cpu trace").enumerations
    };
    let mut closest = |rays: &[Ray]| trace(&serial, rays, TraceOptions::new(Bvh2Method::Stack)).0;
    let sets = ray_sets(&named.scene, RaySetSize { width: 40, height: 30, uniform_count: 1500 }, &mut closest);
    let leaves = PrimLeaves::new(&prepared.bvh);
    for params in settings() {
        for set in &sets {
            for query in Query::ALL {
                let reference = trace(&serial, &set.rays, TraceOptions::new(Bvh2Method::Stack).query(query)).0;
                let opts = TraceOptions::new(STREAM).query(query).stream(params).record(Record::Enumerations);
                let (serial_hits, serial_enum) = trace(&serial, &set.rays, opts);
                let (cpu_hits, cpu_enum) = trace(&on_cpu, &set.rays, opts);
                let what = format!("{scene_name} {} {query:?} {params:?}", set.kind.name());
                for (i, ((r, s), c)) in reference.iter().zip(&serial_hits).zip(&cpu_hits).enumerate() {
                    let same = |a: &Hit, b: &Hit| match query {
                        Query::Closest => a.same_as(b),
                        Query::Any => a.is_hit() == b.is_hit(),
                    };
                    assert!(
                        same(r, s) && same(r, c),
                        "{what}: ray {i}: stack {r:?}, serial stream {s:?}, cpu stream {c:?}"
                    );
                }
                assert_eq!(serial_enum, cpu_enum, "{what}: the CPU's enumerations differ from the serial reference's");
                if query == Query::Closest {
                    let ctx = Context { scene: scene_name, ray_set: set.kind.name(), backend: "cpu" };
                    let gaps =
                        check_complete(ctx, &set.rays, STREAM, &reference, &cpu_enum.unwrap_or_default(), &leaves);
                    assert!(
                        gaps.is_empty(),
                        "{what}: {} rays' leaf lists lack their hit's leaf:\n{}",
                        gaps.len(),
                        gaps[0]
                    );
                }
            }
        }
    }
}

#[test]
fn sphereflake_at_every_setting() {
    check("sphereflake");
}

#[test]
fn triangle_soup_at_every_setting() {
    check("triangle_soup");
}

#[test]
fn far_from_origin_at_every_setting() {
    check("far_from_origin");
}
