//! Streams of rays through wide trees (`wide::ray_stream`): every closest hit the single-ray
//! method's bit for bit, every any-hit answer's occlusion the same, and each ray's events the
//! same whichever kernel tests the boxes.

use glam::Vec3;
use raytrail_core::bvh2::NodeRef;
use raytrail_core::intersect::Watertight;
use raytrail_core::method::{Collapse, Query};
use raytrail_core::observe::{Both, Counters, NoObserver, Recorder};
use raytrail_core::wide::ray_stream::{trace_wide_streams, STREAM_RAYS};
use raytrail_core::wide::traverse::{trace_wide_batch, WideRoot};
use raytrail_core::wide::{ChildKernel, FastKernel, ReferenceKernel, WideBvh};
use raytrail_core::{Hit, Ray};

mod common;
use common::{scattered_rays, wide_soup};

/// Rays from all around the soup ([`scattered_rays`]).
fn scattered(n: usize, seed: u64) -> Vec<Ray> {
    scattered_rays(n, seed, Some(97))
}

type Bits = (u32, u32, u32, u32);

fn bits(h: &Hit) -> Bits {
    (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits())
}

/// `rays` in streams with kernel `K`: hits and each ray's counters and nodes.
fn streamed<const W: usize, K: ChildKernel>(
    wide: &WideBvh<W>,
    root: WideRoot,
    rays: &[Ray],
    query: Query,
) -> (Vec<Hit>, Vec<(Counters, Vec<NodeRef>)>) {
    let mut hits = vec![Hit::MISS; rays.len()];
    let mut events = vec![(Counters::default(), Vec::new()); rays.len()];
    let done = |i: usize, o: Both<Counters, Recorder>| events[i] = (o.0, o.1.nodes);
    trace_wide_streams::<W, _, Watertight, K, _>(&wide.memory(), root, rays, &mut hits, query, done);
    (hits, events)
}

fn check<const W: usize>(wide: &WideBvh<W>, scale: f32, seed: u64) -> u64 {
    let root = WideRoot { root: wide.root(), scene_scale: scale, max_steps: u32::MAX };
    let rays = scattered(STREAM_RAYS + 900, seed);
    let mut visited = 0;
    for query in [Query::Closest, Query::Any] {
        let mut alone = vec![Hit::MISS; rays.len()];
        trace_wide_batch::<W, _, Watertight, FastKernel, _>(
            &wide.memory(),
            root,
            &rays,
            &mut alone,
            query,
            &mut NoObserver,
        );
        let (reference, events) = streamed::<W, ReferenceKernel>(wide, root, &rays, query);
        let (fast, fast_events) = streamed::<W, FastKernel>(wide, root, &rays, query);
        for (i, ray) in rays.iter().enumerate() {
            match query {
                Query::Closest => assert_eq!(bits(&reference[i]), bits(&alone[i]), "ray {i}: {ray:?}"),
                Query::Any => assert_eq!(reference[i].is_hit(), alone[i].is_hit(), "ray {i}: {ray:?}"),
            }
            assert_eq!(bits(&fast[i]), bits(&reference[i]), "{query:?} ray {i}");
            assert_eq!(fast_events[i], events[i], "{query:?} ray {i}");
            // A traced ray's first visit is the root; a ray turned away has no events.
            match events[i].1.first() {
                Some(&first) => assert_eq!(first, wide.root().node_ref(), "ray {i}"),
                None => assert!(!ray.is_traceable() || events[i].0 == Counters::default(), "ray {i}"),
            }
        }
        visited += events.iter().map(|e| e.0.internal_nodes).sum::<u64>();
    }
    visited
}

#[test]
fn streams_answer_as_single_rays_and_kernels_agree_on_every_event() {
    let (scale, w4, w8) = wide_soup(3000, 23, Collapse::PullUp);
    let visited = check::<4>(&w4, scale, 5) + check::<8>(&w8, scale, 6);
    assert!(visited > 50_000, "only {visited} internal nodes visited");
}

#[test]
fn broken_inputs_and_empty_batches_trace_without_a_panic() {
    let (scale, _, w8) = wide_soup(200, 3, Collapse::PullUp);
    let root = WideRoot { root: w8.root(), scene_scale: scale, max_steps: u32::MAX };
    let (hits, events) = streamed::<8, FastKernel>(&w8, root, &[], Query::Closest);
    assert!(hits.is_empty() && events.is_empty());
    let nan = Ray::new(Vec3::NAN, Vec3::X, 0.0, 1.0);
    let (hits, _) = streamed::<8, FastKernel>(&w8, root, &[nan; 5], Query::Closest);
    assert!(hits.iter().all(|h| !h.is_hit()));
    // A budget of one step: the root's visit only, no answer, no hang.
    let tight = WideRoot { max_steps: 0, ..root };
    let rays = scattered(300, 9);
    let (_, events) = streamed::<8, FastKernel>(&w8, tight, &rays, Query::Closest);
    assert!(events.iter().all(|e| e.1.len() <= 1));
}
