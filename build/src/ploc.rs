//! The obvhs BVH2 builder (PLOC with parallel reinsertion), converted to raytrail's canonical tree.
//!
//! obvhs builds a binary BVH bottom-up by PLOC (Meister and Bittner 2018: Morton-sorted
//! primitives, each merged with the neighbour within a search window that gives the smallest box),
//! then improves it by parallel reinsertion (Meister and Bittner 2022), collapses subtrees into
//! leaves where the SAH prefers it, and reinserts again.
//!
//! Against [`SahBuilder`] (binned, 16 bins) run with the same traversal cost (3 intersection tests,
//! the cost obvhs's leaf collapse uses), the measured SAH costs were 12% lower on Sponza and 22%
//! lower on the kitchen scene, 5-12% higher on the bunny, the dragon and random triangle soups, and
//! 25-70% higher on flat scenes such as a height-field grid: obvhs scales its Morton codes per
//! axis, so a thin axis gets as many bits as the long ones.
//!
//! The settings are obvhs's `BvhBuildParams::medium_build()` preset, the one obvhs documents as
//! "around the same build time as embree but with faster traversal" and uses in its own examples:
//! PLOC search distance 14 (1 for the first 3 passes), reinsertion of 5% of the nodes before the
//! collapse and 10% after, 64-bit Morton codes, at most 8 primitives per leaf. Every obvhs preset
//! but `fastest_build` runs PLOC with reinsertion; `slow_build` and `very_slow_build` also split
//! triangles into several boxes (spatial pre-splits), which would let one triangle appear in
//! several leaves. raytrail needs every primitive in exactly one leaf with its id equal to its
//! triangle index, so pre-splits stay off (medium_build has them off; we force it regardless). The
//! leaf collapse only regroups obvhs's `primitive_indices` (which map leaf slots to input indices,
//! here the identity input `0..n`), so leaf contents remain triangle indices.
//!
//! The pipeline is obvhs's `build_bvh2_from_tris` without pre-splits, spelled out here so that the
//! debug-build self-check of obvhs (which panics instead of returning an error) does not run and so
//! that the reinsertion stack is sized from the tree's actual depth.
//!
//! Coincident triangles: PLOC merges only mutual nearest neighbours, and among primitives whose
//! boxes tie it merges about one pair per pass: 10,000 copies of one triangle took 2.7 s, 30,000
//! took 22 s, against milliseconds for the SAH builder. Fixed around obvhs, without falling back:
//! PLOC clusters boxes grown by tiny pseudo-random margins that break the ties (`ploc_boxes`);
//! the tree's boxes are recomputed from the triangles as always. Margins cannot separate
//! triangles collapsed to one point: where more than [`MAX_TIED`] boxes stay identical, the tree is
//! built by [`SahBuilder`] instead ([`ploc_fallback`] gives the message).
//!
//! The conversion:
//! - recomputes every box bottom-up from the triangles (leaf: union of its triangles' boxes,
//!   internal node: union of its children's), so that boxes are tight and a child's box lies
//!   inside its parent's exactly, with the same arithmetic as [`Triangle::bounds`];
//! - caps the depth (at most 63, so keys fit in 64 bits), see [`build_ploc`];
//! - hands the result to [`Bvh2::from_nodes`], which renumbers it into canonical pre-order and
//!   validates it.

use glam::Vec3;
use obvhs::bvh2::leaf_collapser::collapse;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::ploc::PlocBuilder;
use obvhs::BvhBuildParams;
use raytrail_core::bvh2::{Bvh2, Bvh2Node, NodeKind, NodeRef, SahBuilder, SahConfig};
use raytrail_core::geometry::Triangle;
use raytrail_core::{Aabb, Error};
use std::collections::HashMap;

/// The deepest tree 64-bit keys allow (root at depth 0).
pub const MAX_KEY_DEPTH: u32 = 63;

/// Levels beyond a perfectly balanced tree that a rebuilt subtree is given, so the SAH builder is
/// rarely forced to end a branch at the cap with an oversized leaf.
const REBUILD_SLACK: u32 = 4;

/// The obvhs settings used: `medium_build`, pre-splits off (see the module documentation).
fn obvhs_params() -> BvhBuildParams {
    BvhBuildParams { pre_split: false, ..BvhBuildParams::medium_build() }
}

/// Builds the canonical tree over `triangles` (primitive id = triangle index) with obvhs's PLOC
/// builder and reinsertion optimizer, with depth at most `max_depth` (values above 63 mean 63).
///
/// Coincident and nearly coincident triangles build in time comparable to well-spread ones: see
/// `ploc_boxes`; more than [`MAX_TIED`] triangles collapsed to one point are built by
/// [`SahBuilder`] ([`ploc_fallback`]).
///
/// Where the obvhs tree is deeper than `max_depth`, the offending subtrees are rebuilt with
/// [`SahBuilder`] capped to the levels left below them. The subtrees chosen are the deepest ones
/// whose rebuild still leaves room for a balanced tree plus a few spare levels, so PLOC's upper
/// levels are kept; if even the root lacks that room, the whole tree is built by [`SahBuilder`].
/// Nodes at the cap become leaves, which may then hold more than the usual 8 primitives.
///
/// Errors: [`Error::EmptyScene`] for no triangles, [`Error::NonFiniteVertex`] for a NaN or
/// infinite coordinate (`vertex` is `3 * triangle + corner`), [`Error::TreeTooLarge`] for more
/// triangles than node references address, and whatever [`Bvh2::from_nodes`] reports.
pub fn build_ploc(triangles: &[Triangle], max_depth: u32) -> Result<Bvh2, Error> {
    if triangles.is_empty() {
        return Err(Error::EmptyScene);
    }
    if triangles.len() >= NodeRef::LIMIT as usize {
        return Err(Error::TreeTooLarge { what: "triangle count", size: triangles.len() });
    }
    // obvhs assumes finite boxes (NaN breaks its Morton codes and indexing).
    for (i, t) in triangles.iter().enumerate() {
        if let Some(corner) = t.v.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFiniteVertex { vertex: 3 * i + corner });
        }
    }
    let cap = max_depth.min(MAX_KEY_DEPTH);
    let boxes = ploc_boxes(triangles);
    if fallback_reason(largest_tie(&boxes)).is_some() {
        return SahBuilder::new(SahConfig { max_depth: cap, ..SahConfig::default() }).build(triangles);
    }
    let built = build_obvhs_on(boxes);
    let tree = Imported::new(&built, triangles)?;
    let rebuild_at = tree.subtrees_to_rebuild(cap);
    let mut rebuilt = HashMap::with_capacity(rebuild_at.len());
    for (node, depth) in rebuild_at {
        let prims = tree.prims_below(node);
        let local: Vec<Triangle> = prims.iter().map(|&p| triangles[p as usize]).collect();
        let config = SahConfig { max_depth: cap - depth, ..SahConfig::default() };
        rebuilt.insert(node, (SahBuilder::new(config).build(&local)?, prims));
    }
    let (nodes, prim_order) = tree.assemble(&rebuilt);
    Bvh2::from_nodes(&nodes, 0, prim_order)
}

/// A 64-bit mix (SplitMix64's finaliser).
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The boxes PLOC clusters: each triangle's box grown about its centre by a pseudo-random margin
/// of at most 2^-10 of its largest side (or of 2^-20 of its largest coordinate, for a triangle
/// collapsed to a point).
///
/// PLOC merges mutual nearest neighbours only. Where neighbouring boxes are equal or nearly so
/// (coincident triangles; a stack of equal triangles so close that the areas of their unions
/// round to the same float), the distances tie, every node picks the same side, and a pass merges about one pair:
/// PLOC then takes as many passes as there are triangles (10,000 copies of one triangle: 2.7 s;
/// 30,000: 22 s; a stack of 30,000 spaced 1e-5 apart: 7 s). The margins break the ties at random,
/// so that a constant share of the nodes pairs up in each pass, and barely move the distances of
/// boxes that differ. The clustering is all they affect: the centres, hence the Morton order,
/// are unchanged, and [`Imported::new`] recomputes every box from the triangles.
fn ploc_boxes(triangles: &[Triangle]) -> Vec<obvhs::aabb::Aabb> {
    triangles
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let b = t.bounds();
            let r = (mix(i as u64 ^ 0x9E37_79B9_7F4A_7C15) >> 40) as f32 * (1.0 / (1u32 << 24) as f32);
            let magnitude = b.min.abs().max(b.max.abs()).max_element();
            let size = (b.extent().max_element() * (1.0 / 1024.0)).max(magnitude * (1.0 / (1u32 << 20) as f32));
            let pad = Vec3::splat(r * size);
            obvhs::aabb::Aabb { min: (b.min - pad).into(), max: (b.max + pad).into() }
        })
        .collect()
}

/// The most triangles whose `ploc_boxes` may be identical before [`build_ploc`] falls back to
/// [`SahBuilder`]: margins cannot break ties between triangles collapsed to one point (no margin
/// at the origin, a few float steps elsewhere), and a tie of `k` boxes costs PLOC about `k`
/// passes.
pub const MAX_TIED: usize = 256;

/// The largest number of identical boxes among `boxes`, in O(n log n).
fn largest_tie(boxes: &[obvhs::aabb::Aabb]) -> usize {
    let mut keys: Vec<[u32; 6]> = boxes
        .iter()
        .map(|b| {
            let (lo, hi) = (b.min.to_array(), b.max.to_array());
            [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]].map(f32::to_bits)
        })
        .collect();
    keys.sort_unstable();
    keys.chunk_by(|a, b| a == b).map(<[[u32; 6]]>::len).max().unwrap_or(0)
}

/// Why [`build_ploc`] builds `triangles` with [`SahBuilder`] instead of PLOC, if it does (for a
/// caller to print): more than [`MAX_TIED`] of them are points at one place.
pub fn ploc_fallback(triangles: &[Triangle]) -> Option<String> {
    fallback_reason(largest_tie(&ploc_boxes(triangles)))
}

fn fallback_reason(tie: usize) -> Option<String> {
    (tie > MAX_TIED).then(|| {
        format!(
            "{tie} triangles are points at one place, which PLOC clusters in time quadratic in their number;              the SAH builder builds this tree instead"
        )
    })
}

/// Runs obvhs: PLOC (on `ploc_boxes`), reinsertion, leaf collapse, reinsertion.
#[cfg(test)]
fn build_obvhs(triangles: &[Triangle]) -> obvhs::bvh2::Bvh2 {
    build_obvhs_on(ploc_boxes(triangles))
}

/// Runs obvhs on the boxes of `ploc_boxes`: PLOC, reinsertion, leaf collapse, reinsertion.
fn build_obvhs_on(boxes: Vec<obvhs::aabb::Aabb>) -> obvhs::bvh2::Bvh2 {
    let p = obvhs_params();
    let indices: Vec<u32> = (0..boxes.len() as u32).collect();
    let mut bvh = PlocBuilder::with_capacity(boxes.len()).build(
        p.ploc_search_distance,
        &boxes,
        indices,
        p.sort_precision,
        p.search_depth_threshold,
    );
    let mut reinsertion = ReinsertionOptimizer::default();
    // Reinsertion's search stack holds 2 * `max_depth` entries and panics (or, in its fixed-size
    // variant, overwrites) beyond that. PLOC sets `max_depth` from its pass count, which a deepening
    // reinsertion can exceed: re-derive it from the actual depth before each pass.
    bvh.max_depth = bvh.max_depth.max(2 * obvhs_depth(&bvh) + 2);
    reinsertion.run(&mut bvh, p.reinsertion_batch_ratio, None);
    collapse(&mut bvh, p.max_prims_per_leaf.clamp(1, 255), p.collapse_traversal_cost);
    bvh.max_depth = bvh.max_depth.max(2 * obvhs_depth(&bvh) + 2);
    reinsertion.run(&mut bvh, p.reinsertion_batch_ratio * p.post_collapse_reinsertion_batch_ratio_multiplier, None);
    bvh
}

/// Depth of an obvhs tree (root 0), iteratively; stops early on out-of-range links, which
/// [`Imported::new`] reports.
fn obvhs_depth(bvh: &obvhs::bvh2::Bvh2) -> usize {
    let mut deepest = 0;
    let mut todo = vec![(0usize, 0usize)];
    while let Some((i, d)) = todo.pop() {
        let Some(n) = bvh.nodes.get(i) else { continue };
        deepest = deepest.max(d);
        // A well-formed tree never holds more pending nodes than it has; a cyclic one stops here.
        if !n.is_leaf() && todo.len() <= bvh.nodes.len() {
            let c = n.first_index as usize;
            todo.push((c, d + 1));
            todo.push((c + 1, d + 1));
        }
    }
    deepest
}

/// The obvhs tree in raytrail node form, still in obvhs's indexing (children `first_index` and
/// `first_index + 1`, leaves indexing `prim_order`), with recomputed boxes and per-node figures.
struct Imported {
    nodes: Vec<Bvh2Node>,
    /// obvhs's `primitive_indices`: leaf slot -> triangle index.
    prim_order: Vec<u32>,
    /// Subtree height per node (leaf 0).
    height: Vec<u32>,
    /// Primitives below each node.
    count: Vec<u32>,
}

impl Imported {
    /// Checks the obvhs tree's links and recomputes its boxes bottom-up from the triangles.
    fn new(bvh: &obvhs::bvh2::Bvh2, triangles: &[Triangle]) -> Result<Self, Error> {
        let n = bvh.nodes.len();
        if n == 0 || bvh.primitive_indices.len() != triangles.len() {
            return Err(Error::MalformedTree("obvhs returned a tree over a different primitive count"));
        }
        let mut nodes = Vec::with_capacity(n);
        for node in &bvh.nodes {
            if !node.valid() {
                return Err(Error::MalformedTree("obvhs left an invalid node"));
            }
            let kind = if node.is_leaf() {
                let end = node.first_index as usize + node.prim_count as usize;
                let prims = bvh.primitive_indices.get(node.first_index as usize..end);
                if prims.is_none_or(|p| p.iter().any(|&p| p as usize >= triangles.len())) {
                    return Err(Error::MalformedTree("obvhs leaf references a primitive out of range"));
                }
                NodeKind::Leaf { first: node.first_index, count: node.prim_count }
            } else {
                if node.first_index as usize + 1 >= n {
                    return Err(Error::MalformedTree("obvhs child index out of range"));
                }
                NodeKind::Internal { left: node.first_index, right: node.first_index + 1 }
            };
            nodes.push(Bvh2Node { bounds: Aabb::EMPTY, kind });
        }
        // Pre-order from the root, each node at most once; children come after their parent, so
        // the reverse order visits children before parents.
        let mut order = Vec::with_capacity(n);
        let mut seen = vec![false; n];
        let mut todo = vec![0u32];
        while let Some(i) = todo.pop() {
            if std::mem::replace(&mut seen[i as usize], true) {
                return Err(Error::MalformedTree("obvhs tree reaches a node twice"));
            }
            order.push(i);
            if let NodeKind::Internal { left, right } = nodes[i as usize].kind {
                todo.push(right);
                todo.push(left);
            }
        }
        let mut height = vec![0u32; n];
        let mut count = vec![0u32; n];
        for &i in order.iter().rev() {
            let i = i as usize;
            match nodes[i].kind {
                NodeKind::Leaf { first, count: c } => {
                    let prims = &bvh.primitive_indices[first as usize..(first + c) as usize];
                    nodes[i].bounds = prims.iter().fold(Aabb::EMPTY, |b, &p| b.union(triangles[p as usize].bounds()));
                    count[i] = c;
                }
                NodeKind::Internal { left, right } => {
                    let (l, r) = (left as usize, right as usize);
                    nodes[i].bounds = nodes[l].bounds.union(nodes[r].bounds);
                    height[i] = 1 + height[l].max(height[r]);
                    count[i] = count[l] + count[r];
                }
            }
        }
        Ok(Self { nodes, prim_order: bvh.primitive_indices.clone(), height, count })
    }

    /// The roots (and their depths) of the subtrees to rebuild so that no node is deeper than
    /// `cap`: descend from the root while a too-deep node's too-deep children each have room for
    /// a balanced tree plus [`REBUILD_SLACK`] levels, rebuild where they do not.
    fn subtrees_to_rebuild(&self, cap: u32) -> Vec<(u32, u32)> {
        // Depth of a balanced tree over `n` primitives with one per leaf: ceil(log2(n)).
        let balanced = |n: u32| u32::BITS - n.saturating_sub(1).leading_zeros();
        let fits = |i: u32, depth: u32| depth + self.height[i as usize] <= cap;
        let mut out = Vec::new();
        let mut todo = vec![(0u32, 0u32)];
        while let Some((i, depth)) = todo.pop() {
            if fits(i, depth) {
                continue;
            }
            let NodeKind::Internal { left, right } = self.nodes[i as usize].kind else {
                continue; // Leaves have height 0 and always fit where they are reached.
            };
            let room = cap.saturating_sub(depth + 1);
            let fixable = |c: u32| fits(c, depth + 1) || balanced(self.count[c as usize]) + REBUILD_SLACK <= room;
            if fixable(left) && fixable(right) {
                todo.push((left, depth + 1));
                todo.push((right, depth + 1));
            } else {
                out.push((i, depth));
            }
        }
        out
    }

    /// The triangle indices below node `i`.
    fn prims_below(&self, i: u32) -> Vec<u32> {
        let mut prims = Vec::with_capacity(self.count[i as usize] as usize);
        let mut todo = vec![i];
        while let Some(i) = todo.pop() {
            match self.nodes[i as usize].kind {
                NodeKind::Leaf { first, count } => {
                    prims.extend_from_slice(&self.prim_order[first as usize..(first + count) as usize])
                }
                NodeKind::Internal { left, right } => todo.extend([right, left]),
            }
        }
        prims
    }

    /// The final nodes (root at 0) and primitive order: the imported tree with each rebuilt
    /// subtree grafted in place of the original, primitive runs laid out afresh.
    fn assemble(&self, rebuilt: &HashMap<u32, (Bvh2, Vec<u32>)>) -> (Vec<Bvh2Node>, Vec<u32>) {
        let mut nodes: Vec<Bvh2Node> = Vec::with_capacity(self.nodes.len());
        let mut prims: Vec<u32> = Vec::with_capacity(self.prim_order.len());
        // (imported node, slot in `nodes` of the parent and whether this is its right child)
        let mut todo: Vec<(u32, Option<(usize, bool)>)> = vec![(0, None)];
        while let Some((i, patch)) = todo.pop() {
            let at = nodes.len() as u32;
            if let Some((parent, is_right)) = patch {
                if let NodeKind::Internal { left, right } = &mut nodes[parent].kind {
                    *(if is_right { right } else { left }) = at;
                }
            }
            if let Some((sub, global)) = rebuilt.get(&i) {
                // A canonical tree is self-contained: shift its node and primitive indices.
                let base = prims.len() as u32;
                prims.extend(sub.prim_order().iter().map(|&local| global[local as usize]));
                nodes.extend(sub.nodes().iter().map(|n| Bvh2Node {
                    bounds: n.bounds,
                    kind: match n.kind {
                        NodeKind::Internal { left, right } => NodeKind::Internal { left: left + at, right: right + at },
                        NodeKind::Leaf { first, count } => NodeKind::Leaf { first: first + base, count },
                    },
                }));
                continue;
            }
            let node = self.nodes[i as usize];
            match node.kind {
                NodeKind::Leaf { first, count } => {
                    let start = prims.len() as u32;
                    prims.extend_from_slice(&self.prim_order[first as usize..(first + count) as usize]);
                    nodes.push(Bvh2Node { bounds: node.bounds, kind: NodeKind::Leaf { first: start, count } });
                }
                NodeKind::Internal { left, right } => {
                    let slot = nodes.len();
                    nodes.push(Bvh2Node {
                        bounds: node.bounds,
                        kind: NodeKind::Internal { left: u32::MAX, right: u32::MAX },
                    });
                    todo.push((right, Some((slot, true))));
                    todo.push((left, Some((slot, false))));
                }
            }
        }
        (nodes, prims)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// A small deterministic generator (xorshift), so the tests need no dependency.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
        fn vec(&mut self) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next())
        }
    }

    fn random_triangles(n: usize, seed: u64) -> Vec<Triangle> {
        let mut rng = Rng(seed);
        (0..n)
            .map(|_| {
                let c = rng.vec() * 100.0;
                Triangle::new(c + rng.vec() * 2.0, c + rng.vec() * 2.0, c + rng.vec() * 2.0)
            })
            .collect()
    }

    fn grid(n: usize) -> Vec<Triangle> {
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (i as f32, j as f32);
                let h = |x: f32, y: f32| (x * 0.3).sin() * (y * 0.2).cos();
                let p = |x: f32, y: f32| Vec3::new(x, y, h(x, y));
                t.push(Triangle::new(p(x, y), p(x + 1.0, y), p(x, y + 1.0)));
                t.push(Triangle::new(p(x + 1.0, y), p(x + 1.0, y + 1.0), p(x, y + 1.0)));
            }
        }
        t
    }

    /// SAH cost relative to the root's area, with intersection cost 1 and traversal cost `ct`.
    fn sah_cost(bvh: &Bvh2, ct: f64) -> f64 {
        let nodes = bvh.nodes();
        let cost: f64 = nodes
            .iter()
            .map(|n| {
                let area = f64::from(n.bounds.half_area());
                match n.kind {
                    NodeKind::Internal { .. } => ct * area,
                    NodeKind::Leaf { count, .. } => area * f64::from(count),
                }
            })
            .sum();
        cost / f64::from(nodes[0].bounds.half_area())
    }

    /// Everything the conversion promises, checked on the canonical tree.
    fn check(bvh: &Bvh2, triangles: &[Triangle], max_depth: u32) {
        let nodes = bvh.nodes();
        let mut order = bvh.prim_order().to_vec();
        order.sort_unstable();
        assert_eq!(order, (0..triangles.len() as u32).collect::<Vec<_>>(), "every primitive exactly once");
        assert!(bvh.stats().depth <= max_depth.min(63));
        for n in nodes {
            match n.kind {
                NodeKind::Internal { left, right } => {
                    let (l, r) = (nodes[left as usize].bounds, nodes[right as usize].bounds);
                    assert!(n.bounds.contains(&l) && n.bounds.contains(&r));
                    assert_eq!(n.bounds, l.union(r), "tight internal box");
                }
                NodeKind::Leaf { first, count } => {
                    let tight = bvh.prim_order()[first as usize..(first + count) as usize]
                        .iter()
                        .fold(Aabb::EMPTY, |b, &p| b.union(triangles[p as usize].bounds()));
                    assert_eq!(n.bounds, tight, "tight leaf box");
                }
            }
        }
    }

    #[test]
    fn random_triangles_and_a_grid_give_valid_tight_trees_of_sah_quality() {
        for (name, tris) in [("random 4000", random_triangles(4000, 7)), ("grid 64x64x2", grid(64))] {
            let ploc = build_ploc(&tris, 63).unwrap();
            check(&ploc, &tris, 63);
            assert!(ploc.stats().max_leaf_size <= 8);
            // obvhs collapses leaves with traversal cost 3 (intersection 1, per triangle);
            // SahBuilder's default is 1, per block of four. Compare each cost model against the
            // SAH builder run with it, per triangle.
            for ct in [1.0f32, 3.0] {
                let sah = SahBuilder::new(SahConfig { traversal_cost: ct, leaf_block: 1, ..SahConfig::default() })
                    .build(&tris)
                    .unwrap();
                let (cp, cs) = (sah_cost(&ploc, f64::from(ct)), sah_cost(&sah, f64::from(ct)));
                println!(
                    "{name}, traversal cost {ct}: SAH cost PLOC {cp:.2} (depth {}, {} leaves), SahBuilder {cs:.2} \
                     (depth {}, {} leaves), ratio {:.3}",
                    ploc.stats().depth,
                    ploc.stats().leaves,
                    sah.stats().depth,
                    sah.stats().leaves,
                    cp / cs
                );
                assert!(cp < 2.0 * cs, "{name}: PLOC cost {cp} far above SAH {cs}");
            }
        }
    }

    #[test]
    fn tiny_inputs_work_and_empty_is_an_error() {
        assert_eq!(build_ploc(&[], 63).unwrap_err(), Error::EmptyScene);
        let one = [Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
        let bvh = build_ploc(&one, 63).unwrap();
        assert_eq!(bvh.len(), 1);
        assert_eq!(bvh.nodes()[0].kind, NodeKind::Leaf { first: 0, count: 1 });
        assert_eq!(bvh.nodes()[0].bounds, one[0].bounds());
        for n in 2..20 {
            let tris = random_triangles(n, n as u64);
            check(&build_ploc(&tris, 63).unwrap(), &tris, 63);
        }
        // A point-sized triangle: zero extent everywhere.
        let point = [Triangle::new(Vec3::ONE, Vec3::ONE, Vec3::ONE); 3];
        check(&build_ploc(&point, 63).unwrap(), &point, 63);
    }

    #[test]
    fn coincident_triangles_work() {
        let tris = vec![Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y); 1000];
        let bvh = build_ploc(&tris, 63).unwrap();
        check(&bvh, &tris, 63);
    }

    /// Coincident and nearly coincident triangles build within a second (100,000 copies of one
    /// triangle took PLOC over a minute, 30,000 took 22 s, a stack of 30,000 spaced 1e-5 apart 7 s):
    /// the margins of `ploc_boxes` break PLOC's ties.
    #[test]
    fn coincident_and_nearly_coincident_triangles_build_fast() {
        let one = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
        let shifted = |d: Vec3| Triangle::new(one.v[0] + d, one.v[1] + d, one.v[2] + d);
        let mut mixed = random_triangles(5000, 5);
        mixed.extend(std::iter::repeat_n(one, 30_000));
        let near: Vec<Triangle> = (0..30_000).map(|i| shifted(Vec3::splat(i as f32 * 1e-12))).collect();
        let stack: Vec<Triangle> = (0..30_000).map(|i| shifted(Vec3::new(0.0, 0.0, i as f32 * 1e-5))).collect();
        let points = vec![Triangle::new(Vec3::ONE, Vec3::ONE, Vec3::ONE); 30_000];
        assert!(ploc_fallback(&points).is_some_and(|m| m.contains("SAH builder")));
        for (name, tris) in
            [("copies", vec![one; 100_000]), ("mixed", mixed), ("near", near), ("stack", stack), ("points", points)]
        {
            assert_eq!(ploc_fallback(&tris).is_some(), name == "points", "{name}");
            let start = std::time::Instant::now();
            let bvh = build_ploc(&tris, 63).unwrap();
            assert!(start.elapsed() < std::time::Duration::from_secs(1), "{name}: {:?}", start.elapsed());
            check(&bvh, &tris, 63);
        }
    }

    #[test]
    fn non_finite_vertices_are_errors() {
        let mut tris = random_triangles(10, 3);
        tris[4].v[2].y = f32::NAN;
        assert_eq!(build_ploc(&tris, 63).unwrap_err(), Error::NonFiniteVertex { vertex: 14 });
        tris[4].v[2].y = 0.0;
        tris[0].v[0].x = f32::INFINITY;
        assert_eq!(build_ploc(&tris, 63).unwrap_err(), Error::NonFiniteVertex { vertex: 0 });
    }

    #[test]
    fn depth_caps_are_honoured() {
        let tris = random_triangles(4000, 11);
        let free = build_ploc(&tris, 63).unwrap();
        for cap in [0, 1, 5, 12, free.stats().depth - 1, 1000] {
            let bvh = build_ploc(&tris, cap).unwrap();
            check(&bvh, &tris, cap);
        }
        assert_eq!(build_ploc(&tris, 0).unwrap().len(), 1);
        // One level short of a near-balanced tree leaves no room below the root: all is rebuilt.
        let imported = Imported::new(&build_obvhs(&tris), &tris).unwrap();
        assert!(imported.subtrees_to_rebuild(free.stats().depth).is_empty());
        assert_eq!(imported.subtrees_to_rebuild(free.stats().depth - 1), vec![(0, 0)]);
    }

    #[test]
    fn a_scene_forcing_a_deep_tree_is_capped_at_63() {
        // Triangles at geometrically growing distances along a line: nearest-neighbour clustering
        // merges them one by one into a chain hundreds of levels deep.
        let tris: Vec<Triangle> = (0..300)
            .map(|i| {
                let x = 1.1f32.powi(i);
                Triangle::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x * 1.01, 0.0, 0.0), Vec3::new(x, x * 0.01, 0.0))
            })
            .collect();
        let raw = build_obvhs(&tris);
        assert!(obvhs_depth(&raw) > 63, "the scene must defeat the cap: obvhs depth {}", obvhs_depth(&raw));
        // A chain keeps its upper links; only its deep end is rebuilt, with room to spare.
        let roots = Imported::new(&raw, &tris).unwrap().subtrees_to_rebuild(63);
        assert!(
            !roots.is_empty() && roots.iter().all(|&(_, depth)| depth > 0 && depth + REBUILD_SLACK < 63),
            "{roots:?}"
        );
        let bvh = build_ploc(&tris, 63).unwrap();
        check(&bvh, &tris, 63);
        let bvh = build_ploc(&tris, 20).unwrap();
        check(&bvh, &tris, 20);
    }
}
