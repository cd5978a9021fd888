//! The suite must catch a broken method. Each test corrupts one thing a backtracking decision
//! depends on, in a copy of a prepared scene, and requires the checks to report mismatches for
//! the methods that read it (and none for the methods that do not).

use raytrail_conformance::check::{check_ray_set, Context, Difference, Mismatch};
use raytrail_conformance::rays::{primary, uniform_random, RAY_SEED};
use raytrail_conformance::scenes::sphereflake;
use raytrail_core::bvh2::traverse::trace_ray;
use raytrail_core::bvh2::{BinaryNode, BvhMemory, LeafWord, NodeRef, SahBuilder, SliceMemory};
use raytrail_core::hash::HashShape;
use raytrail_core::intersect::Watertight;
use raytrail_core::method::{Bvh2Method, Method, Query};
use raytrail_core::observe::NoObserver;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::Trace;
use raytrail_core::Ray;
use raytrail_cpu::CpuBackend;
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::Arc;

fn setup() -> (PreparedScene, Vec<Ray>) {
    let scene = sphereflake(2);
    let bvh = SahBuilder::default().build(scene.triangles()).unwrap();
    let prepared = PreparedScene::new(&scene, bvh, &Method::ALL).unwrap();
    let mut rays = primary(&scene, 48, 48);
    rays.extend(uniform_random(&scene, 2000, RAY_SEED));
    (prepared, rays)
}

fn check(prepared: PreparedScene, rays: &[Ray]) -> Vec<Mismatch> {
    let backend = CpuBackend::new();
    let scene = backend.prepare(Arc::new(prepared)).unwrap();
    let ctx = Context { scene: "sphereflake(2), corrupted", ray_set: "primary+uniform", backend: "cpu" };
    check_ray_set(&backend, &scene, ctx, rays, &Method::ALL).unwrap()
}

fn methods_caught(m: &[Mismatch]) -> Vec<Method> {
    let mut v: Vec<Method> = m.iter().map(|x| x.method).collect();
    v.sort();
    v.dedup();
    v
}

#[test]
fn the_uncorrupted_scene_conforms() {
    let (prepared, rays) = setup();
    let m = check(prepared, &rays);
    assert!(m.is_empty(), "{}", m[0]);
}

#[test]
fn swapped_uncle_links_are_caught() {
    // Every refill of the register now takes the grand uncle where the trail says uncle and
    // vice versa: one backtracking decision flipped.
    let (mut prepared, rays) = setup();
    for n in &mut prepared.uncles.as_mut().unwrap().nodes {
        n.links.swap(0, 1);
    }
    let m = check(prepared, &rays);
    let caught = methods_caught(&m);
    for method in [
        Method::Bvh2(Bvh2Method::Uncle),
        Method::Bvh2(Bvh2Method::Hash),
        Method::Bvh2(Bvh2Method::HashDisjoint),
        Method::Bvh2(Bvh2Method::HashResume),
    ] {
        assert!(caught.contains(&method), "{method} not caught; caught {caught:?}");
    }
    assert!(
        !caught.contains(&Method::Bvh2(Bvh2Method::Stack))
            && !caught.contains(&Method::Bvh2(Bvh2Method::ParentSibling)),
        "{caught:?}"
    );
    let shown = m.iter().find(|x| matches!(x.difference, Difference::Enumeration { .. })).unwrap().to_string();
    assert!(shown.contains("enumerations part at position"), "{shown}");
    eprintln!("caught as expected, e.g.:\n{shown}");
}

/// Counts which hash cells and displacement entries traversal reads.
struct Tally<'a> {
    inner: SliceMemory<'a>,
    cells: RefCell<HashMap<u32, u32>>,
    direct: RefCell<HashMap<u32, u32>>,
}

impl BvhMemory for Tally<'_> {
    fn node(&self, i: u32) -> BinaryNode {
        self.inner.node(i)
    }
    fn leaf_word(&self, o: u32) -> LeafWord {
        self.inner.leaf_word(o)
    }
    fn displacement(&self, slot: u32) -> i32 {
        let d = self.inner.displacement(slot);
        if d < 0 {
            *self.direct.borrow_mut().entry(slot).or_default() += 1;
        }
        d
    }
    fn hash_cell(&self, slot: u32) -> u32 {
        *self.cells.borrow_mut().entry(slot).or_default() += 1;
        self.inner.hash_cell(slot)
    }
    fn hash_shape(&self) -> HashShape {
        self.inner.hash_shape()
    }
}

/// The hash cell and the direct displacement entry the hash method reads most often.
fn busiest(prepared: &PreparedScene, rays: &[Ray]) -> (u32, u32) {
    let tally = Tally {
        inner: prepared.memory(Bvh2Method::Hash).unwrap(),
        cells: Default::default(),
        direct: Default::default(),
    };
    let root = prepared.root(Bvh2Method::Hash).unwrap();
    for r in rays {
        trace_ray::<u32, _, Watertight, _>(Bvh2Method::Hash, &tally, root, r, Query::Closest, &mut NoObserver);
    }
    let top = |m: &RefCell<HashMap<u32, u32>>| *m.borrow().iter().max_by_key(|(k, v)| (**v, u32::MAX - **k)).unwrap().0;
    (top(&tally.cells), top(&tally.direct))
}

#[test]
fn one_wrong_hash_cell_is_caught() {
    let (mut prepared, rays) = setup();
    let (cell, _) = busiest(&prepared, &rays);
    let h = prepared.hash.as_mut().unwrap();
    // Point the cell at the root: a plausible address, the wrong node.
    h.tables.cells[cell as usize] = NodeRef::internal(0).0;
    let caught = methods_caught(&check(prepared, &rays));
    assert!(
        caught.contains(&Method::Bvh2(Bvh2Method::Hash)) && caught.contains(&Method::Bvh2(Bvh2Method::HashDisjoint)),
        "{caught:?}"
    );
    assert!(!caught.contains(&Method::Bvh2(Bvh2Method::Uncle)), "{caught:?}");
}

#[test]
fn one_wrong_direct_displacement_is_caught() {
    let (mut prepared, rays) = setup();
    let (_, slot) = busiest(&prepared, &rays);
    let h = prepared.hash.as_mut().unwrap();
    h.tables.displacement[slot as usize] = raytrail_core::hash::encode_direct(NodeRef::internal(0));
    let caught = methods_caught(&check(prepared, &rays));
    assert!(caught.contains(&Method::Bvh2(Bvh2Method::Hash)), "{caught:?}");
}
