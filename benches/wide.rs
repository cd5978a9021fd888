//! Criterion bench of Guthe 2014's claims for wide BVHs, measured on the CPU with one thread.
//!
//! `cargo bench --bench wide` traces the same rays through the core's traversal loops directly
//! (no backend, no threads) and reports time per batch; compare variants side by side within one
//! run. Each group is one scene and ray type:
//!
//! - (a) 4-wide and 8-wide (Guthe's pull-up) against the binary tree (the BVH2 stack method);
//! - (b) any-hit rays with the hit children pushed unsorted (Sec. 4.2, the default) against
//!   sorted nearest first (`*-sorted-any`);
//! - (c) leaves tested four triangles at once against one at a time (`*-one-tri`);
//! - (d) the naive collapse (every second level removed) against the pull-up (`bvh4-naive`).
//!
//! Rays: 256x192 primary rays in Morton order and the diffuse bounces of their hits (closest
//! hit); shadow rays to the default light and short ambient-occlusion rays (any hit). Scenes
//! come from `../shared/scenes` (or `RAYTRAIL_SCENES`).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode, Throughput};
use raytrail::core::bvh2::traverse::trace_batch;
use raytrail::core::intersect::{SlabRay, Watertight};
use raytrail::core::key::KeyWidth;
use raytrail::core::method::{Bvh2Method, Method, Query, WideMethod};
use raytrail::core::observe::NoObserver;
use raytrail::core::prepared::PreparedScene;
use raytrail::core::scene::Scene;
use raytrail::core::wide::traverse::{trace_wide_batch, WideRoot};
use raytrail::core::wide::{ChildHits, ChildKernel, FastKernel, WideNode, WideSliceMemory, WideTree};
use raytrail::core::{Hit, Ray};
use raytrail::Builder;
use raytrail_conformance::paths::load_mesh_scene;
use raytrail_conformance::rays::{default_light, diffuse, primary, scene_epsilon, shadow, RAY_SEED};
use std::time::Duration;

const SCENES: &[&str] = &["bunny.obj", "sponza.obj"];
const METHODS: &[Method] = &[
    Method::Bvh2(Bvh2Method::Stack),
    Method::Wide(WideMethod::BVH4),
    Method::Wide(WideMethod::BVH8),
    Method::Wide(WideMethod::BVH4_NAIVE),
    Method::Wide(WideMethod::BVH8_SAH),
];
/// Length of an ambient-occlusion ray as a fraction of the scene's diagonal (the CLI bench's).
const AO_RADIUS: f32 = 0.05;

/// [`FastKernel`] with its two switches set by hand: `SORTED_ANY` (any-hit queries also visit hit
/// children nearest first: what Guthe's unsorted occlusion, Sec. 4.2, saves) and `BLOCKS` (leaves
/// four triangles at once: what the unrolled triangle loop, Sec. 4, saves).
struct Switched<const BLOCKS: bool, const SORTED_ANY: bool>;

impl<const B: bool, const S: bool> ChildKernel for Switched<B, S> {
    const BLOCKS: bool = B;
    const SORTED_ANY: bool = S;

    #[inline(always)]
    fn test<const W: usize>(node: &WideNode<W>, slab: &SlabRay, tmin: f32, tmax: f32) -> ChildHits<W> {
        FastKernel::test(node, slab, tmin, tmax)
    }

    #[inline(always)]
    fn order<const W: usize>(hits: &ChildHits<W>, order: &mut [u32; W]) -> usize {
        FastKernel::order(hits, order)
    }
}

/// Sorted occlusion, leaves in blocks.
type SortedAnyKernel = Switched<true, true>;
/// Unsorted occlusion, leaves one triangle at a time.
type OneTriKernel = Switched<false, false>;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kernel {
    Fast,
    SortedAny,
    OneTri,
}

/// One traversal: the binary stack method, or a wide tree with a child kernel.
#[derive(Clone, Copy, Debug)]
enum Variant {
    Binary,
    Wide(WideMethod, Kernel),
}

impl Variant {
    fn label(self) -> String {
        match self {
            Variant::Binary => "stack".to_string(),
            Variant::Wide(m, Kernel::Fast) => m.name().to_string(),
            Variant::Wide(m, Kernel::SortedAny) => format!("{}-sorted-any", m.name()),
            Variant::Wide(m, Kernel::OneTri) => format!("{}-one-tri", m.name()),
        }
    }
}

/// The variants traced for `query`: sorted any-hit only where it differs from the default.
fn variants(query: Query) -> Vec<Variant> {
    let mut v = vec![
        Variant::Binary,
        Variant::Wide(WideMethod::BVH4, Kernel::Fast),
        Variant::Wide(WideMethod::BVH8, Kernel::Fast),
        Variant::Wide(WideMethod::BVH4_NAIVE, Kernel::Fast),
        Variant::Wide(WideMethod::BVH8_SAH, Kernel::Fast),
        Variant::Wide(WideMethod::BVH4, Kernel::OneTri),
        Variant::Wide(WideMethod::BVH8, Kernel::OneTri),
    ];
    if query.is_any() {
        v.extend([
            Variant::Wide(WideMethod::BVH4, Kernel::SortedAny),
            Variant::Wide(WideMethod::BVH8, Kernel::SortedAny),
        ]);
    }
    v
}

/// Traces `rays` into `hits` with `variant`, one thread, watertight triangle test.
fn trace(p: &PreparedScene, variant: Variant, rays: &[Ray], hits: &mut [Hit], query: Query) {
    match variant {
        Variant::Binary => {
            let m = Bvh2Method::Stack;
            let (mem, root) = (p.memory(m).expect("memory"), p.root(m).expect("root"));
            match p.key_width() {
                KeyWidth::W32 => {
                    trace_batch::<u32, _, Watertight, _>(m, &mem, root, rays, hits, query, &mut NoObserver)
                }
                KeyWidth::W64 => {
                    trace_batch::<u64, _, Watertight, _>(m, &mem, root, rays, hits, query, &mut NoObserver)
                }
            }
        }
        Variant::Wide(m, kernel) => {
            let root = p.wide_root(m).expect("root");
            match p.wide_tree(m).expect("tree") {
                WideTree::Four(t) => wide::<4>(&t.memory(), root, kernel, rays, hits, query),
                WideTree::Eight(t) => wide::<8>(&t.memory(), root, kernel, rays, hits, query),
            }
        }
    }
}

fn wide<const W: usize>(
    mem: &WideSliceMemory<'_, W>,
    root: WideRoot,
    kernel: Kernel,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
) {
    let obs = &mut NoObserver;
    match kernel {
        Kernel::Fast => trace_wide_batch::<W, _, Watertight, FastKernel, NoObserver>(mem, root, rays, hits, query, obs),
        Kernel::SortedAny => {
            trace_wide_batch::<W, _, Watertight, SortedAnyKernel, NoObserver>(mem, root, rays, hits, query, obs)
        }
        Kernel::OneTri => {
            trace_wide_batch::<W, _, Watertight, OneTriKernel, NoObserver>(mem, root, rays, hits, query, obs)
        }
    }
}

/// Short any-hit rays: the diffuse bounces cut to `AO_RADIUS` of the scene's diagonal.
fn ambient_occlusion(bounces: &[Ray], scene: &Scene) -> Vec<Ray> {
    let radius = AO_RADIUS * scene.bounds().extent().length();
    bounces.iter().map(|r| Ray::new(r.origin(), r.dir(), r.tmin, radius)).collect()
}

/// Rays whose answer differs from the binary tree's: another closest hit, or another occlusion.
fn disagreements(expected: &[Hit], got: &[Hit], query: Query) -> usize {
    let same = |a: &Hit, b: &Hit| match query {
        Query::Closest => (a.prim, a.t.to_bits()) == (b.prim, b.t.to_bits()),
        Query::Any => a.is_hit() == b.is_hit(),
    };
    expected.iter().zip(got).filter(|(a, b)| !same(a, b)).count()
}

fn bench(c: &mut Criterion) {
    for file in SCENES {
        let named = match load_mesh_scene(file) {
            Ok(s) => s,
            Err(e) => panic!("{e} (the bench reads ../shared/scenes or RAYTRAIL_SCENES)"),
        };
        let bvh = Builder::Sah.build(&named.scene).expect("build");
        let prepared = PreparedScene::new(&named.scene, bvh, METHODS).expect("prepare");
        let bounds = named.scene.bounds();
        let prim = primary(&named.scene, 256, 192);
        let mut hits = vec![Hit::MISS; prim.len()];
        trace(&prepared, Variant::Binary, &prim, &mut hits, Query::Closest);
        let bounce = diffuse(&prim, &hits, &named.scene, RAY_SEED);
        let shadows = shadow(&prim, &hits, default_light(bounds), scene_epsilon(bounds));
        let ao = ambient_occlusion(&bounce, &named.scene);
        let sets = [
            ("primary", &prim, Query::Closest),
            ("diffuse", &bounce, Query::Closest),
            ("shadow", &shadows, Query::Any),
            ("ao", &ao, Query::Any),
        ];
        for (kind, rays, query) in sets {
            let mut expected = vec![Hit::MISS; rays.len()];
            trace(&prepared, Variant::Binary, rays, &mut expected, query);
            let mut group = c.benchmark_group(format!("wide/{}/{kind}", named.name));
            group.throughput(Throughput::Elements(rays.len() as u64));
            group.sample_size(10);
            group.sampling_mode(SamplingMode::Flat);
            group.warm_up_time(Duration::from_millis(500));
            group.measurement_time(Duration::from_secs(2));
            let mut out = vec![Hit::MISS; rays.len()];
            for variant in variants(query) {
                trace(&prepared, variant, rays, &mut out, query);
                let n = disagreements(&expected, &out, query);
                eprintln!(
                    "{}/{kind} {} ({} rays): {n} answers differ from stack",
                    named.name,
                    variant.label(),
                    rays.len()
                );
                group.bench_with_input(BenchmarkId::from_parameter(variant.label()), rays, |b, rays| {
                    b.iter(|| trace(&prepared, variant, rays, &mut out, query))
                });
            }
            group.finish();
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
