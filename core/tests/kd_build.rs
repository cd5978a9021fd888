//! The SAH kd-tree builder: tree validity, coverage (every triangle meeting a leaf's box is in the
//! leaf) and a brute-force ray check, on generated scenes and the real meshes.
//!
//! The real meshes are read from `../shared/scenes` beside the workspace (`RAYTRAIL_SCENES`
//! overrides it); a missing one is skipped with a printed line, or fails where
//! `RAYTRAIL_REQUIRE_SCENES=1`. Build times
//! and tree figures: `cargo test --release -p raytrail-core --test kd_build -- --ignored
//! --nocapture`.
#![cfg(feature = "std")]

// In a module so that `cargo test kd` selects these tests.
mod common;

mod kd {
    use crate::common::scene_file;
    use glam::Vec3;
    use raytrail_core::geometry::Triangle;
    use raytrail_core::intersect::{TriangleTest, Watertight};
    use raytrail_core::kd::{KdBuilder, KdConfig, KdTree};
    use raytrail_core::{Aabb, Hit, Ray};

    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            self.0 >> 11
        }
        fn f(&mut self) -> f32 {
            (self.next() >> 29) as f32 / (1u64 << 24) as f32
        }
        fn v(&mut self) -> Vec3 {
            Vec3::new(self.f(), self.f(), self.f())
        }
        fn below(&mut self, n: usize) -> usize {
            (self.next() % n as u64) as usize
        }
    }

    // ---------------------------------------------------------------------------------------------
    // Scenes

    fn soup(n: usize, seed: u64, scale: f32, offset: Vec3) -> Vec<Triangle> {
        let mut r = Rng(seed);
        (0..n)
            .map(|_| {
                let c = r.v() * 10.0;
                let s = 0.05 + r.f() * 2.0;
                let t = [c, c + (r.v() - 0.5) * s, c + (r.v() - 0.5) * s];
                Triangle { v: t.map(|p| p * scale + offset) }
            })
            .collect()
    }

    /// An `n` x `n` grid of unit squares in the plane z = 0, two triangles each (shared edges).
    fn grid(n: usize) -> Vec<Triangle> {
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (i as f32, j as f32);
                let p = |dx: f32, dy: f32| Vec3::new(x + dx, y + dy, 0.0);
                t.push(Triangle::new(p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)));
                t.push(Triangle::new(p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)));
            }
        }
        t
    }

    /// Axis-aligned squares stacked along each axis (planar triangles exactly in candidate planes),
    /// coincident duplicates, and walls meeting the stacks at their edges.
    fn stacks() -> Vec<Triangle> {
        let mut t = Vec::new();
        let square = |axis: usize, at: f32, lo: f32, hi: f32, t: &mut Vec<Triangle>| {
            let p = |u: f32, v: f32| {
                let mut q = [0.0; 3];
                q[axis] = at;
                q[(axis + 1) % 3] = u;
                q[(axis + 2) % 3] = v;
                Vec3::from(q)
            };
            t.push(Triangle::new(p(lo, lo), p(hi, lo), p(hi, hi)));
            t.push(Triangle::new(p(lo, lo), p(hi, hi), p(lo, hi)));
        };
        for axis in 0..3 {
            for k in 0..12 {
                square(axis, k as f32 * 0.25, 0.0, 3.0, &mut t);
            }
            // Duplicates and a small square inside a big one's plane.
            square(axis, 1.0, 0.0, 3.0, &mut t);
            square(axis, 1.5, 1.0, 1.25, &mut t);
        }
        // A box room around it.
        for axis in 0..3 {
            square(axis, -1.0, -1.0, 4.0, &mut t);
            square(axis, 4.0, -1.0, 4.0, &mut t);
        }
        t
    }

    /// Everything in the plane z = 0.5: a flat scene box.
    fn flat() -> Vec<Triangle> {
        let mut r = Rng(7);
        (0..400)
            .map(|_| {
                let c = r.v() * 8.0;
                let p = |d: Vec3| Vec3::new(c.x + d.x, c.y + d.y, 0.5);
                Triangle::new(p(Vec3::ZERO), p(r.v() - 0.3), p(r.v() - 0.6))
            })
            .collect()
    }

    /// Degenerate triangles (points, segments) among ordinary ones.
    fn degenerate() -> Vec<Triangle> {
        let mut t = soup(200, 11, 1.0, Vec3::ZERO);
        let mut r = Rng(12);
        for _ in 0..100 {
            let a = r.v() * 10.0;
            let b = r.v() * 10.0;
            t.push(Triangle::new(a, a, a));
            t.push(Triangle::new(a, b, (a + b) * 0.5));
        }
        t
    }

    /// Long thin triangles crossing the scene in every direction.
    fn slivers() -> Vec<Triangle> {
        let mut r = Rng(21);
        (0..300)
            .map(|_| {
                let a = r.v() * 10.0;
                let b = r.v() * 10.0;
                Triangle::new(a, b, a + (r.v() - 0.5) * 0.01)
            })
            .collect()
    }

    fn scene_bounds(tris: &[Triangle]) -> Aabb {
        tris.iter().fold(Aabb::EMPTY, |b, t| b.union(t.bounds()))
    }

    // ---------------------------------------------------------------------------------------------
    // Checks

    /// A leaf and its cell, found by descending from the scene bounds.
    struct Leaf {
        node: u32,
        cell: Aabb,
        prims: Vec<u32>,
    }

    fn leaves(tree: &KdTree) -> Vec<Leaf> {
        let mut out = Vec::new();
        let mut todo = vec![(0u32, tree.bounds())];
        while let Some((i, cell)) = todo.pop() {
            let n = tree.nodes()[i as usize];
            if n.is_leaf() {
                let prims = tree.prims()[n.first() as usize..(n.first() + n.count()) as usize].to_vec();
                out.push(Leaf { node: i, cell, prims });
            } else {
                let (a, s) = (n.axis(), n.value);
                assert!(s > cell.min[a] && s < cell.max[a], "plane {s} outside cell {cell:?} on axis {a}");
                let (mut lo, mut hi) = (cell, cell);
                lo.max[a] = s;
                hi.min[a] = s;
                todo.push((n.below(), lo));
                todo.push((n.below() + 1, hi));
            }
        }
        out
    }

    fn overlaps(a: &Aabb, b: &Aabb) -> bool {
        a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
    }

    /// Whether the triangle meets the closed box (separating axis test in f64; touching counts).
    fn triangle_meets_box(t: &Triangle, b: &Aabb) -> bool {
        let c = [0, 1, 2].map(|k| (b.min[k] as f64 + b.max[k] as f64) * 0.5);
        let h = [0, 1, 2].map(|k| (b.max[k] as f64 - b.min[k] as f64) * 0.5);
        let v = t.v.map(|p| [p.x as f64 - c[0], p.y as f64 - c[1], p.z as f64 - c[2]]);
        let sub = |p: [f64; 3], q: [f64; 3]| [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
        let cross = |p: [f64; 3], q: [f64; 3]| {
            [p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]]
        };
        let dot = |p: [f64; 3], q: [f64; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
        let separated = |axis: [f64; 3]| {
            let p = v.map(|x| dot(x, axis));
            let r = h[0] * axis[0].abs() + h[1] * axis[1].abs() + h[2] * axis[2].abs();
            let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
            lo > r || hi < -r
        };
        let e = [sub(v[1], v[0]), sub(v[2], v[1]), sub(v[0], v[2])];
        let units = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        if units.iter().any(|&u| separated(u)) || separated(cross(e[0], e[1])) {
            return false;
        }
        !e.iter().any(|&ei| units.iter().any(|&u| separated(cross(ei, u))))
    }

    /// Tree shape, leaf contents and coverage:
    /// - planes inside their cells, leaf references sorted and unique;
    /// - every triangle in at least one leaf whose cell meets its bounds;
    /// - every triangle meeting a leaf's closed cell (exact test) is in that leaf.
    fn check_coverage(tris: &[Triangle], tree: &KdTree) {
        let scene = scene_bounds(tris);
        assert_eq!(tree.bounds(), scene);
        let leaves = leaves(tree);
        let mut found = vec![false; tris.len()];
        for leaf in &leaves {
            assert!(leaf.prims.windows(2).all(|w| w[0] < w[1]), "leaf {} references unsorted or twice", leaf.node);
            for &p in &leaf.prims {
                found[p as usize] |= overlaps(&tris[p as usize].bounds(), &leaf.cell);
            }
        }
        if let Some(p) = found.iter().position(|&f| !f) {
            panic!("triangle {p} ({:?}) is in no leaf whose cell meets its bounds", tris[p]);
        }
        // Coverage: for each triangle, the leaves reached through cells meeting its bounds.
        let nodes = tree.nodes();
        let mut leaf_at = std::collections::HashMap::new();
        for (k, l) in leaves.iter().enumerate() {
            leaf_at.insert(l.node, k);
        }
        for (p, t) in tris.iter().enumerate() {
            let tb = t.bounds();
            let mut todo = vec![(0u32, scene)];
            while let Some((i, cell)) = todo.pop() {
                let n = nodes[i as usize];
                if n.is_leaf() {
                    if triangle_meets_box(t, &cell) {
                        let leaf = &leaves[leaf_at[&i]];
                        assert!(
                            leaf.prims.binary_search(&(p as u32)).is_ok(),
                            "triangle {p} ({t:?}) meets leaf {i}'s cell {cell:?} but is not in it"
                        );
                    }
                    continue;
                }
                let (a, s) = (n.axis(), n.value);
                if tb.min[a] <= s {
                    let mut c = cell;
                    c.max[a] = s;
                    todo.push((n.below(), c));
                }
                if tb.max[a] >= s {
                    let mut c = cell;
                    c.min[a] = s;
                    todo.push((n.below() + 1, c));
                }
            }
        }
    }

    /// The segment `[t0, t1]` of the ray inside the box, in f64, or `None`.
    fn segment_in_box(o: [f64; 3], d: [f64; 3], b: &Aabb, pad: f64, t0: f64, t1: f64) -> Option<(f64, f64)> {
        let (mut t0, mut t1) = (t0, t1);
        for k in 0..3 {
            let (lo, hi) = (b.min[k] as f64 - pad, b.max[k] as f64 + pad);
            if d[k] == 0.0 {
                if o[k] < lo || o[k] > hi {
                    return None;
                }
                continue;
            }
            let (a, c) = ((lo - o[k]) / d[k], (hi - o[k]) / d[k]);
            t0 = t0.max(a.min(c));
            t1 = t1.min(a.max(c));
        }
        (t0 <= t1).then_some((t0, t1))
    }

    /// Reference traversal: every leaf whose closed cell (padded by `pad` against rounding in this
    /// test) the ray's segment overlaps, by recursion on the cells.
    fn visit(tree: &KdTree, i: u32, cell: Aabb, ray: &Ray, pad: f64, out: &mut Vec<u32>) {
        let o = ray.origin.map(|x| x as f64);
        let d = ray.dir.map(|x| x as f64);
        let (t0, t1) = (ray.tmin as f64, ray.tmax as f64);
        if segment_in_box(o, d, &cell, pad, t0.max(-1e300), t1.min(1e300)).is_none() {
            return;
        }
        let n = tree.nodes()[i as usize];
        if n.is_leaf() {
            out.push(i);
            return;
        }
        let (a, s) = (n.axis(), n.value);
        let (mut lo, mut hi) = (cell, cell);
        lo.max[a] = s;
        hi.min[a] = s;
        visit(tree, n.below(), lo, ray, pad, out);
        visit(tree, n.below() + 1, hi, ray, pad, out);
    }

    fn closest<'a>(tris: &[Triangle], prims: impl Iterator<Item = &'a u32>, ray: &Ray) -> Hit {
        let r = Watertight::prepare(ray);
        let mut best = Hit::MISS;
        for &p in prims {
            let [a, b, c] = tris[p as usize].v;
            if let Some(h) = Watertight::intersect(&r, a, b, c, ray.tmin, ray.tmax) {
                if best.is_beaten_by(h.t, p) {
                    best = Hit { t: h.t, prim: p, u: h.u, v: h.v };
                }
            }
        }
        best
    }

    /// Rays aimed at triangle points (vertices, edge points, interiors), random rays, axis-parallel
    /// rays through vertices with signed zeros, and rays from and within split planes.
    fn rays(tris: &[Triangle], tree: &KdTree, n: usize, seed: u64) -> Vec<Ray> {
        let mut r = Rng(seed);
        let b = tree.bounds();
        let size = b.extent().max_element().max(f32::MIN_POSITIVE);
        let lo = b.min - size * 0.3;
        let span = b.extent() + size * 0.6;
        let inner: Vec<_> = tree.nodes().iter().filter(|n| !n.is_leaf()).copied().collect();
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            let t = tris[r.below(tris.len())].v;
            let (u, v) = match r.below(4) {
                0 => [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)][r.below(3)],
                1 => {
                    let u = r.f();
                    [(u, 0.0), (0.0, u), (u, 1.0 - u)][r.below(3)]
                }
                _ => {
                    let (u, v) = (r.f(), r.f());
                    if u + v > 1.0 {
                        (1.0 - u, 1.0 - v)
                    } else {
                        (u, v)
                    }
                }
            };
            let target = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v;
            let origin = lo + r.v() * span;
            match r.below(8) {
                // Aimed, ending exactly at the target or running on.
                0 => out.push(Ray::new(origin, target - origin, 0.0, 1.0)),
                1 | 2 => out.push(Ray::new(origin, target - origin, 0.0, f32::INFINITY)),
                // Random.
                3 => out.push(Ray::new(origin, r.v() - 0.5, 0.0, f32::INFINITY)),
                // Axis-parallel through the target, signed zeros.
                4 => {
                    let a = r.below(3);
                    let mut d = [if r.below(2) == 0 { 0.0 } else { -0.0 }; 3];
                    d[(a + 1) % 3] = if r.below(2) == 0 { 0.0 } else { -0.0 };
                    let sign = if r.below(2) == 0 { 1.0 } else { -1.0 };
                    d[a] = sign;
                    let mut o = target;
                    o[a] = if sign > 0.0 { lo[a] } else { lo[a] + span[a] };
                    out.push(Ray::new(o, Vec3::from(d), 0.0, f32::INFINITY));
                }
                // From a split plane, or lying in it, towards the target.
                _ if !inner.is_empty() => {
                    let p = inner[r.below(inner.len())];
                    let mut o = origin;
                    o[p.axis()] = p.value;
                    let mut d = target - o;
                    if r.below(2) == 0 {
                        d[p.axis()] = 0.0;
                    }
                    out.push(Ray::new(o, d, 0.0, f32::INFINITY));
                }
                _ => out.push(Ray::new(origin, target - origin, 0.0, f32::INFINITY)),
            }
        }
        out
    }

    /// Closest hits through the reference traversal equal the brute-force closest hits; returns
    /// the number of hits.
    fn check_rays(tris: &[Triangle], tree: &KdTree, n: usize, seed: u64) -> usize {
        let b = tree.bounds();
        let scale = b.min.abs().max(b.max.abs()).max_element() as f64;
        let mut leaves = Vec::new();
        let mut hits = 0;
        for (k, ray) in rays(tris, tree, n, seed).iter().enumerate() {
            if !ray.is_traceable() {
                continue;
            }
            // The tree's outer faces are padded by a few float epsilons of the ray's reach, as the
            // traversals pad the scene box: the triangle test may report a hit a few ulps
            // outside a triangle, so outside a flat scene box. The split planes get only a pad
            // against rounding in this `f64` test: the builder's margin must cover the rest.
            let reach = scale + ray.origin().abs().max_element() as f64;
            let outer = (2.0 * f32::EPSILON as f64 * reach) as f32;
            let root = Aabb { min: b.min - outer, max: b.max + outer };
            leaves.clear();
            visit(tree, 0, root, ray, 1e-12 * reach, &mut leaves);
            let prims: Vec<u32> = leaves
                .iter()
                .flat_map(|&i| {
                    let n = tree.nodes()[i as usize];
                    tree.prims()[n.first() as usize..(n.first() + n.count()) as usize].iter().copied()
                })
                .collect();
            let got = closest(tris, prims.iter(), ray);
            let want = closest(tris, (0..tris.len() as u32).collect::<Vec<_>>().iter(), ray);
            assert!(got.same_as(&want), "ray {k} {ray:?}: tree {got:?}, brute force {want:?}");
            hits += want.is_hit() as usize;
        }
        hits
    }

    fn check(name: &str, tris: &[Triangle], config: KdConfig, rays: usize) -> KdTree {
        let tree = KdBuilder::new(config).build(tris).unwrap_or_else(|e| panic!("{name}: {e}"));
        let s = tree.stats();
        assert_eq!(s.leaves, s.inner_nodes + 1, "{name}");
        assert!(s.depth <= config.depth_cap(tris.len()), "{name}: depth {} over the cap", s.depth);
        check_coverage(tris, &tree);
        let hits = check_rays(tris, &tree, rays, 0x5eed ^ tris.len() as u64);
        // Scenes that can be hit are hit (huge or tiny coordinates overflow the triangle test).
        let hittable = tris.iter().any(|t| (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]).length() > 1e-6);
        assert!(hits > 0 || !hittable || rays == 0, "{name}: no ray hit anything");
        tree
    }

    // ---------------------------------------------------------------------------------------------
    // Generated scenes

    #[test]
    fn single_triangle() {
        let t = [Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)];
        let tree = check("single", &t, KdConfig::default(), 500);
        assert_eq!(tree.nodes().len(), 1);
        assert_eq!(tree.prims(), &[0]);
    }

    #[test]
    fn random_soups() {
        for seed in 1..4 {
            let tree = check("soup", &soup(1500, seed, 1.0, Vec3::ZERO), KdConfig::default(), 3000);
            assert!(tree.stats().inner_nodes > 100);
        }
    }

    #[test]
    fn grid_with_shared_edges() {
        let tree = check("grid", &grid(30), KdConfig::default(), 3000);
        // A flat scene box, split only in x and y.
        assert!(tree.nodes().iter().all(|n| n.is_leaf() || n.axis() != 2));
    }

    #[test]
    fn axis_aligned_stacks_and_coincident_planes() {
        let tris = stacks();
        let tree = check("stacks", &tris, KdConfig::default(), 4000);
        // Walls on all three axes: planes on all three, beside the walls (never on a triangle's
        // plane, so each wall lies on one side).
        let planes: Vec<_> = tree.nodes().iter().filter(|n| !n.is_leaf()).collect();
        for axis in 0..3 {
            assert!(planes.iter().any(|n| n.axis() == axis));
        }
        assert!(planes.iter().all(|n| !tris.iter().any(|t| t.v.iter().all(|v| v[n.axis()] == n.value))));
    }

    #[test]
    fn coplanar_axis_aligned_scene() {
        check("flat", &flat(), KdConfig::default(), 3000);
    }

    #[test]
    fn degenerate_triangles_are_kept() {
        let tris = degenerate();
        check("degenerate", &tris, KdConfig::default(), 2000);
        // All coincident: no split helps; one leaf with everything.
        let same = vec![Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y); 50];
        let tree = check("coincident", &same, KdConfig::default(), 300);
        assert_eq!(tree.prims().len(), 50);
        // A scene that is a single point or a segment.
        let point = vec![Triangle::new(Vec3::ONE, Vec3::ONE, Vec3::ONE); 10];
        check("point", &point, KdConfig::default(), 10);
        let segment: Vec<_> = (0..20).map(|i| Triangle::new(Vec3::ZERO, Vec3::X * i as f32, Vec3::X)).collect();
        check("segment", &segment, KdConfig::default(), 10);
    }

    #[test]
    fn long_thin_triangles() {
        check("slivers", &slivers(), KdConfig::default(), 3000);
    }

    #[test]
    fn huge_tiny_and_far_coordinates() {
        check("huge", &soup(400, 5, 1e30, Vec3::ZERO), KdConfig::default(), 500);
        check("tiny", &soup(400, 6, 1e-30, Vec3::ZERO), KdConfig::default(), 500);
        check("far", &soup(800, 7, 1.0, Vec3::splat(-3.0e5)), KdConfig::default(), 2000);
        check(
            "mixed",
            &[soup(100, 8, 1e-3, Vec3::ZERO), soup(100, 9, 1e4, Vec3::ZERO)].concat(),
            KdConfig::default(),
            2000,
        );
    }

    #[test]
    fn settings_are_honoured() {
        let tris = soup(2000, 3, 1.0, Vec3::ZERO);
        for cfg in [
            KdConfig { max_depth: 3, ..KdConfig::default() },
            KdConfig { bins: 2, ..KdConfig::default() },
            KdConfig { bins: 0, ..KdConfig::default() },
            KdConfig { empty_bonus: 1.0, ..KdConfig::default() },
            KdConfig { traversal_cost: 4.0, intersection_cost: 1.0, ..KdConfig::default() },
            KdConfig { traversal_cost: 0.1, intersection_cost: 1.0, max_depth: 63, ..KdConfig::default() },
        ] {
            let tree = check("settings", &tris, cfg, 500);
            if cfg.max_depth == 3 {
                assert_eq!(tree.stats().depth, 3);
            }
        }
        // A costlier traversal gives a shallower tree.
        let cheap = KdBuilder::new(KdConfig { traversal_cost: 0.25, ..KdConfig::default() }).build(&tris).unwrap();
        let dear = KdBuilder::new(KdConfig { traversal_cost: 8.0, ..KdConfig::default() }).build(&tris).unwrap();
        assert!(dear.stats().leaves < cheap.stats().leaves);
    }

    #[test]
    fn deterministic() {
        let tris = soup(3000, 4, 1.0, Vec3::ZERO);
        let a = KdBuilder::default().build(&tris).unwrap();
        let b = KdBuilder::default().build(&tris).unwrap();
        assert_eq!(a.nodes(), b.nodes());
        assert_eq!(a.prims(), b.prims());
    }

    // ---------------------------------------------------------------------------------------------
    // Real meshes

    fn load(file: &str) -> Option<Vec<Triangle>> {
        let path = scene_file(file)?;
        let mesh = raytrail_mesh::load(&path).unwrap_or_else(|e| panic!("{e}"));
        Some(mesh.to_scene().unwrap_or_else(|e| panic!("{file}: {e}")).triangles().to_vec())
    }

    #[test]
    fn cornell_box_and_teapot() {
        for file in ["cornell_box.obj", "teapot.obj"] {
            let Some(tris) = load(file) else { continue };
            check(file, &tris, KdConfig::default(), 3000);
        }
    }

    /// Expected SAH cost of a tree (Horn et al.'s costs: 1 per traversal step and per triangle
    /// test), relative to the root's area, for comparing builds.
    fn sah_cost(tree: &KdTree, cfg: &KdConfig) -> f64 {
        let area = |b: &Aabb| {
            let e = [0, 1, 2].map(|k| b.max[k] as f64 - b.min[k] as f64);
            e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
        };
        let root = area(&tree.bounds());
        let mut cost = 0.0;
        let mut todo = vec![(0u32, tree.bounds())];
        while let Some((i, cell)) = todo.pop() {
            let n = tree.nodes()[i as usize];
            let a = area(&cell) / root;
            if n.is_leaf() {
                cost += a * cfg.intersection_cost as f64 * n.count() as f64;
            } else {
                cost += a * cfg.traversal_cost as f64;
                let (mut lo, mut hi) = (cell, cell);
                lo.max[n.axis()] = n.value;
                hi.min[n.axis()] = n.value;
                todo.push((n.below(), lo));
                todo.push((n.below() + 1, hi));
            }
        }
        cost
    }

    /// Leaves at the depth cap and the references they hold.
    fn leaves_at_cap(tree: &KdTree, cap: u32) -> (usize, usize) {
        let (mut leaves, mut refs) = (0, 0);
        let mut todo = vec![(0u32, 0u32)];
        while let Some((i, depth)) = todo.pop() {
            let n = tree.nodes()[i as usize];
            if n.is_leaf() {
                if depth == cap {
                    leaves += 1;
                    refs += n.count() as usize;
                }
            } else {
                todo.push((n.below(), depth + 1));
                todo.push((n.below() + 1, depth + 1));
            }
        }
        (leaves, refs)
    }

    /// Build times and tree figures of the real meshes (the figures of the report). Run in release
    /// or in the test profile; `KD_SCENES=a.obj,b.ply.gz` picks meshes, `KD_REPS` the builds per
    /// mesh (median and minimum reported), `KD_DEPTH` overrides the depth cap, `KD_RAYS=n` adds
    /// the brute-force ray check.
    #[test]
    #[ignore = "timing: run with --ignored --nocapture"]
    fn real_meshes_figures() {
        let files = std::env::var("KD_SCENES").unwrap_or_else(|_| {
            "teapot.obj,bunny.obj,sponza.obj,kitchen.obj,dragon_vrip_res2.ply.gz,dragon_vrip.ply.gz".into()
        });
        let reps = std::env::var("KD_REPS").map_or(3, |v| v.parse().unwrap());
        let rays = std::env::var("KD_RAYS").map_or(0, |v| v.parse().unwrap());
        let mut cfg = KdConfig::default();
        if let Ok(v) = std::env::var("KD_DEPTH") {
            cfg.max_depth = v.parse().unwrap();
        }
        for file in files.split(',') {
            let Some(tris) = load(file) else { continue };
            let mut times = Vec::new();
            let mut tree = None;
            for _ in 0..reps {
                let start = std::time::Instant::now();
                tree = Some(KdBuilder::new(cfg).build(&tris).unwrap());
                times.push(start.elapsed().as_secs_f64());
            }
            times.sort_by(f64::total_cmp);
            let tree = tree.unwrap();
            let s = tree.stats();
            let cap = cfg.depth_cap(tris.len());
            let (cap_leaves, cap_refs) = leaves_at_cap(&tree, cap);
            println!(
                "{file}: {} tris, build {:.3} s (median of {}, min {:.3}), depth {} (cap {cap}), {} inner, \
                 {} leaves, {} empty, max leaf {}, refs/tri {:.2}, refs/non-empty leaf {:.2}, \
                 {cap_leaves} leaves at the cap with {cap_refs} refs, SAH cost {:.2}, {:.1} MB",
                tris.len(),
                times[times.len() / 2],
                times.len(),
                times[0],
                s.depth,
                s.inner_nodes,
                s.leaves,
                s.empty_leaves,
                s.max_leaf_size,
                s.refs_per_triangle,
                tree.prims().len() as f64 / (s.leaves - s.empty_leaves).max(1) as f64,
                sah_cost(&tree, &cfg),
                tree.bytes() as f64 / 1e6,
            );
            if rays > 0 {
                let hits = check_rays(&tris, &tree, rays, 99);
                println!("  {rays} rays agree with brute force ({hits} hits)");
            }
        }
    }
}
