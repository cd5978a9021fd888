//! The wide trees collapsed from the binary one: every binary leaf kept whole and reached once,
//! child boxes the binary nodes' own, the width respected, and the pull-up's shape against the
//! naive collapse (Guthe 2014, Sec. 4.1), and the SAH-optimal cut's total node area against both.

use raytrail_core::bvh2::{Bvh2, NodeKind, SahBuilder, SahConfig};
use raytrail_core::method::Collapse;
use raytrail_core::wide::{WideBvh, WideChild};

mod common;
use common::soup;

/// Walks the wide tree and checks it against the binary one; returns the binary leaves reached.
fn check<const W: usize>(bvh: &Bvh2, wide: &WideBvh<W>) -> Vec<u32> {
    let mut leaves = Vec::new();
    let mut todo = vec![wide.root()];
    while let Some(c) = todo.pop() {
        match c {
            WideChild::Leaf { first, count } => {
                let id = wide.canonical_id(c.node_ref()).expect("a leaf names a binary leaf");
                let NodeKind::Leaf { first: b_first, count: b_count } = bvh.nodes()[id as usize].kind else {
                    panic!("wide leaf {first} names binary node {id}, not a leaf")
                };
                assert_eq!(first % 4, 0, "leaf {id} starts a block");
                assert_eq!(count, b_count, "leaf {id} kept whole");
                let (w, b) = (first as usize, b_first as usize);
                assert_eq!(&wide.prims()[w..w + count as usize], &bvh.prim_order()[b..b + count as usize], "leaf {id}");
                // The blocks hold the same triangles and ids, lane by lane, and empty lanes after.
                for pos in w..(w + count as usize).next_multiple_of(4) {
                    let block = &wide.blocks()[pos / 4];
                    let lane = block.triangles.lane(pos % 4).map(glam::Vec3::from_array);
                    if pos < w + count as usize {
                        assert_eq!((block.prims[pos % 4], lane), (wide.prims()[pos], wide.triangles()[pos].v), "{pos}");
                    } else {
                        assert!(block.prims[pos % 4] == u32::MAX && lane[0].is_nan(), "empty lane {pos}");
                    }
                }
                leaves.push(id);
            }
            WideChild::Node(n) => {
                let node = &wide.nodes()[n as usize];
                let mut filled = 0;
                for i in 0..W {
                    let Some(child) = node.child_ref(i) else { continue };
                    filled += 1;
                    let id = wide.canonical_id(child.node_ref()).expect("a child names a binary node");
                    let b = bvh.nodes()[id as usize].bounds;
                    assert_eq!(node.child_box(i), (b.min, b.max), "child {i} of node {n} has its binary node's box");
                    todo.push(child);
                }
                assert!(filled >= 2, "node {n} has {filled} children");
                // Filled slots first, largest box first.
                // The same area the builder orders by (the binary node's box is the child's).
                let area = |i: usize| {
                    node.child_ref(i).map(|_| {
                        let (lo, hi) = node.child_box(i);
                        raytrail_core::Aabb::new(lo, hi).half_area()
                    })
                };
                for i in 1..W {
                    match (area(i - 1), area(i)) {
                        (Some(a), Some(b)) => {
                            assert!(a >= b, "node {n}: slot {i} has a larger box than slot {}", i - 1)
                        }
                        (None, Some(_)) => panic!("node {n}: slot {i} filled after an empty slot"),
                        _ => {}
                    }
                }
            }
        }
    }
    leaves.sort_unstable();
    leaves
}

fn binary_leaves(bvh: &Bvh2) -> Vec<u32> {
    (0..bvh.len() as u32).filter(|&i| matches!(bvh.nodes()[i as usize].kind, NodeKind::Leaf { .. })).collect()
}

#[test]
fn every_binary_leaf_is_reached_once_with_its_box_and_triangles() {
    for (seed, leaf) in [(1, 1), (2, 4), (3, 8)] {
        let tris = soup(3000, seed, 2.0);
        let bvh = SahBuilder::new(SahConfig { max_leaf_size: leaf, ..SahConfig::default() }).build(&tris).unwrap();
        let expected = binary_leaves(&bvh);
        for collapse in [Collapse::PullUp, Collapse::EverySecondLevel, Collapse::Optimal] {
            let w4 = WideBvh::<4>::build(&bvh, &tris, collapse).unwrap();
            assert_eq!(check(&bvh, &w4), expected, "4-wide {collapse:?}");
            let w8 = WideBvh::<8>::build(&bvh, &tris, collapse).unwrap();
            assert_eq!(check(&bvh, &w8), expected, "8-wide {collapse:?}");
            assert_eq!(w4.stats().leaves, expected.len());
        }
    }
}

#[test]
fn the_pull_up_fills_nodes_better_than_removing_every_second_level() {
    let tris = soup(20_000, 7, 2.0);
    let bvh = SahBuilder::default().build(&tris).unwrap();
    let internal = bvh.len() - binary_leaves(&bvh).len();
    let pull = WideBvh::<4>::build(&bvh, &tris, Collapse::PullUp).unwrap().stats();
    let naive = WideBvh::<4>::build(&bvh, &tris, Collapse::EverySecondLevel).unwrap().stats();
    let eight = WideBvh::<8>::build(&bvh, &tris, Collapse::PullUp).unwrap().stats();
    // Each pull-up removes one binary node: a 4-wide node stands for up to three.
    assert!(pull.nodes * 3 >= internal && pull.nodes < internal, "{pull:?} from {internal} binary nodes");
    assert!(pull.nodes <= naive.nodes, "pull-up {pull:?}, naive {naive:?}");
    assert!(pull.empty_slots <= naive.empty_slots, "pull-up {pull:?}, naive {naive:?}");
    assert!(eight.nodes < pull.nodes && eight.depth <= pull.depth, "8-wide {eight:?}, 4-wide {pull:?}");
}

#[test]
fn a_single_leaf_tree_is_a_leaf_root() {
    let tris = soup(1, 3, 1.0);
    let bvh = SahBuilder::default().build(&tris).unwrap();
    let w = WideBvh::<4>::build(&bvh, &tris, Collapse::PullUp).unwrap();
    assert_eq!(w.root(), WideChild::Leaf { first: 0, count: 1 });
    assert!(w.nodes().is_empty());
}

/// The total half area of the binary nodes a wide tree's nodes stand for: the part of the
/// surface-area cost that depends on the cut.
fn node_area<const W: usize>(bvh: &Bvh2, wide: &WideBvh<W>) -> f64 {
    (0..wide.nodes().len() as u32)
        .map(|n| {
            let id = wide.canonical_id(WideChild::Node(n).node_ref()).expect("a node names a binary node");
            f64::from(bvh.nodes()[id as usize].bounds.half_area())
        })
        .sum()
}

#[test]
fn the_optimal_cut_has_no_more_node_area_than_either_greedy_collapse() {
    let mut strictly_less = 0;
    for (seed, leaf) in [(11, 1), (12, 4), (13, 8)] {
        let tris = soup(5000, seed, 2.0);
        let bvh = SahBuilder::new(SahConfig { max_leaf_size: leaf, ..SahConfig::default() }).build(&tris).unwrap();
        let areas = |collapse| {
            let a4 = node_area(&bvh, &WideBvh::<4>::build(&bvh, &tris, collapse).unwrap());
            let a8 = node_area(&bvh, &WideBvh::<8>::build(&bvh, &tris, collapse).unwrap());
            (a4, a8)
        };
        let (o4, o8) = areas(Collapse::Optimal);
        for other in [Collapse::PullUp, Collapse::EverySecondLevel] {
            let (g4, g8) = areas(other);
            // Both greedy collapses are cuts the optimum chose among; allow the float sums'
            // rounding.
            assert!(o4 <= g4 * (1.0 + 1e-6), "4-wide: optimal {o4}, {other:?} {g4}");
            assert!(o8 <= g8 * (1.0 + 1e-6), "8-wide: optimal {o8}, {other:?} {g8}");
            strictly_less += usize::from(o4 < g4 * (1.0 - 1e-4)) + usize::from(o8 < g8 * (1.0 - 1e-4));
        }
    }
    // A test that cannot tell the optimum from the pull-up would be no test.
    assert!(strictly_less >= 6, "the optimal cut beat a greedy one only {strictly_less} times of 12");
}
