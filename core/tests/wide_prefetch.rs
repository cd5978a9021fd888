//! Prefetching the hit children of wide nodes: a hint that changes no answer and no event, taken
//! only for incoherent rays over trees larger than the caches (any-hit rays only in packets and
//! streams).

use glam::Vec3;
use raytrail_core::bvh2::NodeRef;
use raytrail_core::intersect::Watertight;
use raytrail_core::method::{Collapse, Query};
use raytrail_core::observe::{Both, Counters, Recorder};
use raytrail_core::wide::packet::{trace_wide_packets, ReferencePacketKernel};
use raytrail_core::wide::ray_stream::trace_wide_streams;
use raytrail_core::wide::traverse::{trace_wide_batch, WideRoot};
use raytrail_core::wide::{
    worth_prefetching, FastKernel, PrefetchingMemory, ReferenceKernel, WideBvh, WideMemory, PREFETCH_ABOVE_BYTES,
};
use raytrail_core::{Hit, Ray};

mod common;
use common::{scattered_rays, wide_soup};

/// Rays from all around the soup ([`scattered_rays`]).
fn scattered(n: usize, seed: u64) -> Vec<Ray> {
    scattered_rays(n, seed, None)
}

/// A pinhole camera's rays in pixel order (coherent).
fn camera(n: usize) -> Vec<Ray> {
    (0..n)
        .map(|i| {
            let (x, y) = ((i % 64) as f32 / 64.0 - 0.5, (i / 64) as f32 / 64.0 - 0.5);
            Ray::new(Vec3::new(5.0, 5.0, -20.0), Vec3::new(x, y, 1.0), 0.0, f32::INFINITY)
        })
        .collect()
}

fn same_as_plain<const W: usize, K: raytrail_core::wide::ChildKernel>(wide: &WideBvh<W>, scale: f32) -> u64 {
    let root = WideRoot { root: wide.root(), scene_scale: scale, max_steps: u32::MAX };
    let mut visited = 0;
    for query in [Query::Closest, Query::Any] {
        for (i, ray) in scattered(1000, 3 + W as u64).iter().enumerate() {
            let (mut plain_hit, mut fetched_hit) = ([Hit::MISS], [Hit::MISS]);
            let mut plain = Both(Counters::default(), Recorder::default());
            let mut fetched = Both(Counters::default(), Recorder::default());
            let one = core::slice::from_ref(ray);
            trace_wide_batch::<W, _, Watertight, K, _>(&wide.memory(), root, one, &mut plain_hit, query, &mut plain);
            let mem = PrefetchingMemory(wide.memory());
            trace_wide_batch::<W, _, Watertight, K, _>(&mem, root, one, &mut fetched_hit, query, &mut fetched);
            let bits = |h: &Hit| (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits());
            assert_eq!(bits(&fetched_hit[0]), bits(&plain_hit[0]), "{query:?} ray {i}: {ray:?}");
            assert_eq!(fetched.1.nodes, plain.1.nodes, "{query:?} ray {i}: {ray:?}");
            assert_eq!(fetched.0, plain.0, "{query:?} ray {i}: {ray:?}");
            visited += plain.0.internal_nodes;
        }
    }
    visited
}

#[test]
fn prefetching_changes_no_answer_and_no_event() {
    let (scale, w4, w8) = wide_soup(3000, 17, Collapse::Optimal);
    let visited = same_as_plain::<4, FastKernel>(&w4, scale)
        + same_as_plain::<8, FastKernel>(&w8, scale)
        + same_as_plain::<8, ReferenceKernel>(&w8, scale);
    assert!(visited > 10_000, "only {visited} internal nodes visited");
}

/// Hits (as bits) and each ray's counters and nodes.
type Traced = (Vec<(u32, u32, u32, u32)>, Vec<(Counters, Vec<NodeRef>)>);

/// How rays share walks: in packets, or in streams.
#[derive(Clone, Copy, Debug)]
enum Shared {
    Packets,
    Streams,
}

/// `rays` traced together (`how`) over `mem`.
fn together<const W: usize, M: WideMemory<W>>(
    how: Shared,
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    query: Query,
) -> Traced {
    let mut hits = vec![Hit::MISS; rays.len()];
    let mut events = vec![(Counters::default(), Vec::new()); rays.len()];
    let done = |i: usize, o: Both<Counters, Recorder>| events[i] = (o.0, o.1.nodes);
    match how {
        Shared::Packets => trace_wide_packets::<W, _, Watertight, FastKernel, ReferencePacketKernel, _>(
            mem, root, rays, &mut hits, query, done,
        ),
        Shared::Streams => {
            trace_wide_streams::<W, _, Watertight, FastKernel, _>(mem, root, rays, &mut hits, query, done)
        }
    }
    (hits.iter().map(|h| (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits())).collect(), events)
}

/// Packets (whose handed-over subtrees prefetch) or streams (whose nodes prefetch their hit
/// children) on prefetching memory: the same answers and each ray's events as on plain memory.
fn together_same_as_plain<const W: usize>(how: Shared, wide: &WideBvh<W>, scale: f32) -> u64 {
    let root = WideRoot { root: wide.root(), scene_scale: scale, max_steps: u32::MAX };
    let rays = scattered(1000, 11 + W as u64);
    let mut visited = 0;
    for query in [Query::Closest, Query::Any] {
        let plain = together(how, &wide.memory(), root, &rays, query);
        let fetched = together(how, &PrefetchingMemory(wide.memory()), root, &rays, query);
        assert_eq!(fetched, plain, "{how:?} {query:?}");
        visited += plain.1.iter().map(|e| e.0.internal_nodes).sum::<u64>();
    }
    visited
}

#[test]
fn prefetching_changes_no_packet_or_stream_answer_and_no_event() {
    let (scale, w4, w8) = wide_soup(3000, 17, Collapse::Optimal);
    for how in [Shared::Packets, Shared::Streams] {
        let visited = together_same_as_plain::<4>(how, &w4, scale) + together_same_as_plain::<8>(how, &w8, scale);
        assert!(visited > 10_000, "{how:?}: only {visited} internal nodes visited");
    }
}

#[test]
fn only_incoherent_rays_over_large_trees_prefetch_and_any_hit_ones_only_in_shared_walks() {
    let large = PREFETCH_ABOVE_BYTES + 1;
    let (scattered, camera) = (scattered(256, 5), camera(256));
    assert!(worth_prefetching(large, &scattered, Query::Closest, false));
    assert!(!worth_prefetching(PREFETCH_ABOVE_BYTES, &scattered, Query::Closest, false), "a tree that fits the caches");
    assert!(!worth_prefetching(large, &scattered, Query::Any, false), "any-hit rays alone");
    assert!(worth_prefetching(large, &scattered, Query::Any, true), "any-hit rays in packets or streams");
    assert!(worth_prefetching(large, &scattered, Query::Closest, true), "closest-hit rays in packets or streams");
    assert!(!worth_prefetching(large, &camera, Query::Any, true), "coherent rays in packets");
    assert!(!worth_prefetching(PREFETCH_ABOVE_BYTES, &scattered, Query::Any, true), "a small tree, in packets");
    assert!(!worth_prefetching(large, &camera, Query::Closest, false), "coherent camera rays");
    // Too few rays to judge, and degenerate directions (zero, NaN), decide without a panic.
    assert!(!worth_prefetching(large, &scattered[..1], Query::Closest, false));
    assert!(!worth_prefetching(large, &[], Query::Closest, false));
    let odd: Vec<Ray> =
        (0..64).map(|i| Ray::new(Vec3::ZERO, if i % 2 == 0 { Vec3::ZERO } else { Vec3::NAN }, 0.0, 1.0)).collect();
    assert!(worth_prefetching(large, &odd, Query::Closest, false), "no pair of these is close");
}
