//! Stress test of the per-ray slack ([`RayContext::t_slack`]): how far a watertight hit's computed
//! `t` strays from the computed slab interval of the triangle's own bounding box.
//!
//! The traversals stay exact (every method finds what a brute-force loop finds) only if, for every
//! hit a triangle test reports, its box passes the slack-widened box test and the disjoint and kd
//! termination rules, which compare a hit in one box with the interval of another. Both hold when
//! the hit strays from its box's interval by at most half the slack on either side
//! (`t_enter - t <= s/2`, `t - t_exit <= s/2`). The derivation in [`RayContext::new`] predicts
//! about 6 units of `EPSILON * reach / |d|` (the slack is 16); this test measures it over hundreds
//! of thousands of hits, many built to be hard: geometry far from the origin, origins on or just
//! off the triangle's plane (secondary rays), triangles in axis planes (flat boxes), rays aimed at
//! edges and vertices, rays nearly parallel to the plane, and direction lengths from 1e-3 to 1e3.

mod common;

use common::Rng;
use glam::Vec3;
use raytrail_core::intersect::{RayContext, SlabRay, TriangleTest, Watertight, SLACK_ULPS};
use raytrail_core::Ray;

/// How a case's ray is made.
#[derive(Clone, Copy, Debug)]
enum Shape {
    /// From a random point of the scene's cube toward a random point of the triangle.
    Aimed,
    /// From a point on the triangle, pushed off its plane by a few ulps or not at all, in a random
    /// direction (a secondary ray).
    FromSurface,
    /// Toward a point of the triangle along a direction almost inside its plane.
    Grazing,
    /// Toward a vertex or a point of an edge exactly.
    EdgeOrVertex,
}

/// What a run saw, in units of `EPSILON * reach / |d|`.
#[derive(Default, Debug)]
struct Seen {
    /// Hits measured.
    hits: u32,
    /// Largest straying (`t_enter - t` or `t - t_exit`) of a hit on a well-shaped triangle (its
    /// smallest altitude at least a tenth of its longest edge): the derivation's regime.
    worst_well_shaped: f64,
    /// Largest straying of any hit.
    worst: f64,
    /// Hits straying more than half the slack.
    beyond_half_slack: u32,
    /// Hits straying more than 32 units (half the slack of 64 units used before).
    beyond_32: u32,
}

/// Whether the triangle's smallest altitude is at least a tenth of its longest edge.
fn well_shaped(v: [Vec3; 3]) -> bool {
    let longest = (v[1] - v[0]).length().max((v[2] - v[1]).length()).max((v[0] - v[2]).length());
    let twice_area = (v[1] - v[0]).cross(v[2] - v[0]).length();
    longest > 0.0 && twice_area / longest >= 0.1 * longest
}

/// A point of the triangle from barycentrics `(b1, b2)`, folded into the triangle.
fn on_triangle(v: [Vec3; 3], mut b1: f32, mut b2: f32) -> Vec3 {
    if b1 + b2 > 1.0 {
        (b1, b2) = (1.0 - b1, 1.0 - b2);
    }
    v[0] + (v[1] - v[0]) * b1 + (v[2] - v[0]) * b2
}

/// A random ray of `shape` for triangle `v` in a scene of half-size `half` around `center`.
fn make_ray(r: &mut Rng, shape: Shape, v: [Vec3; 3], center: Vec3, half: f32) -> Ray {
    let len = 10f32.powf(r.f() * 6.0 - 3.0);
    let target = on_triangle(v, r.f(), r.f());
    let normal = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
    let (origin, dir) = match shape {
        Shape::Aimed => {
            let o = center + (r.v() * 2.0 - 1.0) * half;
            (o, target - o)
        }
        Shape::FromSurface => {
            let ulps = (r.f() * 4.0).floor() * f32::EPSILON * target.abs().max_element();
            let side = if r.f() < 0.5 { -1.0 } else { 1.0 };
            (target + normal * ulps * side, r.v() * 2.0 - 1.0)
        }
        Shape::Grazing => {
            let along = (v[(r.f() * 3.0) as usize % 3] - target).normalize_or_zero();
            let tilt = 10f32.powf(-1.0 - r.f() * 6.0) * if r.f() < 0.5 { -1.0 } else { 1.0 };
            let d = along + normal * tilt;
            (target - d * half * r.f(), d)
        }
        Shape::EdgeOrVertex => {
            let i = (r.f() * 3.0) as usize % 3;
            let p = if r.f() < 0.5 { v[i] } else { v[i] + (v[(i + 1) % 3] - v[i]) * r.f() };
            let o = center + (r.v() * 2.0 - 1.0) * half;
            (o, p - o)
        }
    };
    Ray::new(origin, dir.normalize_or_zero() * len, f32::NEG_INFINITY, f32::INFINITY)
}

/// Measures `cases` random triangles and rays of `shape`, with scenes up to `far` away from the
/// origin (in units of their size).
fn measure(seed: u64, cases: u32, shape: Shape, far: f32) -> Seen {
    let mut r = Rng(seed);
    let mut seen = Seen::default();
    for _ in 0..cases {
        let half = 10f32.powf(r.f() * 6.0 - 3.0);
        let center = (r.v() * 2.0 - 1.0) * half * far * r.f();
        let size = half * 10f32.powf(-r.f() * 4.0);
        let c = center + (r.v() * 2.0 - 1.0) * (half - size);
        let mut v = [c + (r.v() - 0.5) * size, c + (r.v() - 0.5) * size, c + (r.v() - 0.5) * size];
        // Half the triangles lie in an axis plane (a floor, a wall): their boxes are flat, the
        // hardest case, since the box interval shrinks to the plane's own distance.
        if r.f() < 0.5 {
            let axis = (r.f() * 3.0) as usize % 3;
            for p in &mut v {
                p[axis] = c[axis];
            }
        }
        let ray = make_ray(&mut r, shape, v, center, half);
        if !ray.is_traceable() {
            continue;
        }
        let scene_scale = (center.abs() + Vec3::splat(half)).max_element();
        let ctx = RayContext::<Watertight>::new(&ray, scene_scale);
        if !ctx.is_reliable() {
            continue;
        }
        let tri = Watertight::prepare(&ray);
        let Some(h) = Watertight::intersect(&tri, v[0], v[1], v[2], f32::NEG_INFINITY, f32::INFINITY) else {
            continue;
        };
        // The box's raw computed interval: no clamping to a ray interval, no slack.
        let slab = SlabRay { slack: f32::INFINITY, ..SlabRay::new(&ray) };
        let (lo, hi) = (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
        let b = slab.hit(lo, hi, f32::NEG_INFINITY, f32::INFINITY).expect("an infinite slack accepts every box");
        let unit = f64::from(f32::EPSILON) * f64::from(scene_scale + ray.origin().abs().max_element())
            / f64::from(ray.dir().abs().max_element());
        let t = f64::from(h.t);
        let stray = ((f64::from(b.t_enter) - t) / unit).max((t - f64::from(b.t_exit)) / unit);
        seen.hits += 1;
        seen.worst = seen.worst.max(stray);
        if well_shaped(v) {
            seen.worst_well_shaped = seen.worst_well_shaped.max(stray);
        }
        seen.beyond_half_slack += (stray > f64::from(SLACK_ULPS) / 2.0) as u32;
        seen.beyond_32 += (stray > 32.0) as u32;
    }
    seen
}

#[test]
fn hits_stray_from_their_box_by_less_than_half_the_slack() {
    let half = f64::from(SLACK_ULPS) / 2.0;
    let shapes = [Shape::Aimed, Shape::FromSurface, Shape::Grazing, Shape::EdgeOrVertex];
    let (mut hits, mut beyond_half, mut beyond_32) = (0, 0, 0);
    for (i, shape) in shapes.into_iter().enumerate() {
        for (j, far) in [0.0f32, 1.0, 1e3].into_iter().enumerate() {
            let s = measure(0x5EED + (i * 8 + j) as u64, 60_000, shape, far);
            println!(
                "{shape:?}, scene up to {far} sizes from the origin: {} hits; worst straying {:.2} on well-shaped \
                 triangles, {:.2} on any; {} beyond {half}, {} beyond 32 (units of EPSILON * reach / |d|)",
                s.hits, s.worst_well_shaped, s.worst, s.beyond_half_slack, s.beyond_32
            );
            assert!(s.hits > 5_000, "{shape:?}: too few hits ({}) to say anything", s.hits);
            assert!(
                s.worst_well_shaped <= half,
                "{shape:?}, far {far}: a hit on a well-shaped triangle strays from its box by more than half the \
                 slack: {s:?}"
            );
            (hits, beyond_half, beyond_32) =
                (hits + s.hits, beyond_half + s.beyond_half_slack, beyond_32 + s.beyond_32);
        }
    }
    // Slivers (long, thin triangles) seen at an angle amplify the rounding of the edge functions
    // by their aspect ratio; no constant slack covers every one, and the conformance suite checks
    // real meshes end to end. Here they must stay a rare tail.
    println!("all: {hits} hits, {beyond_half} beyond {half} units, {beyond_32} beyond 32 units");
    assert!(
        u64::from(beyond_half) * 10_000 <= u64::from(hits),
        "{beyond_half} of {hits} hits stray from their box by more than half the slack"
    );
}
