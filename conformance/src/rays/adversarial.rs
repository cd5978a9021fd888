//! Adversarial rays: the inputs on which box and triangle tests, reciprocal directions and
//! interval logic go wrong.

use crate::rng::Pcg32;
use glam::Vec3;
use raytrail_core::scene::Scene;
use raytrail_core::Ray;

/// Triangles sampled for vertex, edge and plane rays (all of them in smaller scenes).
const SAMPLED_TRIANGLES: usize = 32;

/// About 1,600 rays (about 200 for a one-triangle scene) built to break traversal, in groups:
/// 1. axis-parallel rays with every sign combination of `+0.0` and `-0.0` in the two zero
///    components, from the scene's center, from outside its corner, and along each axis through
///    sampled vertices exactly;
/// 2. rays aimed exactly at sampled vertices and at edge midpoints (`t = 1` there), rays running
///    along edges within the triangle's plane, and rays starting on a vertex;
/// 3. origins exactly on box planes: the scene box's faces and the planes of sampled vertex
///    coordinates (the planes of leaf boxes), with random directions, directions lying in the plane
///    (a `±0` component: `0 * inf` in a slab test) and along the plane's normal; origins at the
///    box's corners;
/// 4. NaN and infinite origin, direction and interval components; zero directions of all sign
///    combinations;
/// 5. odd intervals: `tmin > tmax`, `tmin = tmax` (at a vertex and elsewhere), negative and
///    infinite `tmin`, `tmax = +0.0` and `-0.0`, `tmax` just short of and just past a vertex;
/// 6. direction magnitudes from about 1e-45 (subnormal) to 1e30, and directions with components
///    20 orders of magnitude apart.
///
/// Most of them are traceable; those that are not ([`Ray::is_traceable`]) must come back as misses.
pub fn adversarial(scene: &Scene, seed: u64) -> Vec<Ray> {
    let mut rng = Pcg32::new(seed, 0xAD);
    let b = scene.bounds();
    let center = b.center();
    let size = match b.extent().max_element() {
        s if s > 0.0 => s,
        _ => 1.0,
    };
    let margin = 0.25 * size;
    let tris = scene.triangles();
    let sample: Vec<usize> = if tris.len() <= SAMPLED_TRIANGLES {
        (0..tris.len()).collect()
    } else {
        (0..SAMPLED_TRIANGLES).map(|_| rng.index(tris.len())).collect()
    };
    let vertices: Vec<Vec3> = sample.iter().flat_map(|&i| tris[i].v).collect();
    // A point well outside the scene, in a random direction.
    let outside = |rng: &mut Pcg32| center + rng.unit_vector() * (2.0 * size);
    let mut out = Vec::new();
    let mut push = |o: Vec3, d: Vec3, tmin: f32, tmax: f32| out.push(Ray::new(o, d, tmin, tmax));

    // 1. Axis-parallel rays with signed zeros.
    let zeros = [(0.0, 0.0), (0.0, -0.0), (-0.0, 0.0), (-0.0, -0.0)];
    let corner = b.min - Vec3::splat(margin);
    for origin in [center, corner] {
        for axis in 0..3 {
            for sign in [1.0f32, -1.0] {
                for (z1, z2) in zeros {
                    push(origin, axis_dir(axis, sign, z1, z2), 0.0, f32::INFINITY);
                }
            }
        }
    }
    for &v in &vertices {
        for axis in 0..3 {
            for sign in [1.0f32, -1.0] {
                // Start outside the box on the same axis line as the vertex, so the ray passes
                // exactly through it.
                let mut o = v;
                o[axis] = if sign > 0.0 { b.min[axis] - margin } else { b.max[axis] + margin };
                let (z1, z2) = zeros[rng.index(4)];
                push(o, axis_dir(axis, sign, z1, z2), 0.0, f32::INFINITY);
            }
        }
    }

    // 2. Through vertices and edge midpoints, along edges, from vertices.
    for &i in &sample {
        let [a, b_, c] = tris[i].v;
        for target in [a, b_, c, (a + b_) * 0.5, (b_ + c) * 0.5, (c + a) * 0.5] {
            let o = outside(&mut rng);
            push(o, target - o, 0.0, f32::INFINITY);
        }
        for (p, q) in [(a, b_), (b_, c), (c, a)] {
            push(p - (q - p), q - p, 0.0, f32::INFINITY);
        }
        push(a, rng.unit_vector(), 0.0, f32::INFINITY);
    }

    // 3. Origins on box planes.
    let mut planes: Vec<(usize, f32)> = (0..3).flat_map(|a| [(a, b.min[a]), (a, b.max[a])]).collect();
    planes.extend(vertices.iter().take(24).enumerate().map(|(k, v)| (k % 3, v[k % 3])));
    let (lo, hi) = (b.min - Vec3::splat(margin), b.max + Vec3::splat(margin));
    for (axis, value) in planes {
        let mut o = rng.in_box(lo, hi);
        o[axis] = value;
        push(o, rng.unit_vector(), 0.0, f32::INFINITY);
        let mut in_plane = center - o;
        in_plane[axis] = if rng.next_u32() & 1 == 0 { 0.0 } else { -0.0 };
        if in_plane.length_squared() > 0.0 {
            push(o, in_plane, 0.0, f32::INFINITY);
        }
        let toward = if value <= center[axis] { 1.0 } else { -1.0 };
        push(o, axis_dir(axis, toward, 0.0, -0.0), 0.0, f32::INFINITY);
    }
    for k in 0..8 {
        let c = Vec3::new(
            if k & 1 == 0 { b.min.x } else { b.max.x },
            if k & 2 == 0 { b.min.y } else { b.max.y },
            if k & 4 == 0 { b.min.z } else { b.max.z },
        );
        push(c, center - c, 0.0, f32::INFINITY);
        push(c, c - center, 0.0, f32::INFINITY);
    }

    // Base rays for the component, interval and magnitude variants: aimed at sampled vertices from
    // outside, so that `t = 1` is at the vertex.
    let bases: Vec<(Vec3, Vec3)> = vertices
        .iter()
        .step_by(3)
        .take(8)
        .map(|&v| {
            let o = outside(&mut rng);
            (o, v - o)
        })
        .collect();

    // 4. Non-finite components and zero directions.
    let (nan, inf) = (f32::NAN, f32::INFINITY);
    for &(o, d) in &bases {
        for axis in 0..3 {
            for bad in [nan, inf, -inf] {
                let mut o2 = o;
                o2[axis] = bad;
                push(o2, d, 0.0, inf);
                let mut d2 = d;
                d2[axis] = bad;
                push(o, d2, 0.0, inf);
            }
        }
        push(o, Vec3::splat(nan), 0.0, inf);
        push(o, Vec3::splat(inf), 0.0, inf);
        for (tmin, tmax) in [(nan, inf), (0.0, nan), (nan, nan), (-inf, inf), (-inf, -inf), (inf, inf), (0.0, -inf)] {
            push(o, d, tmin, tmax);
        }
        for k in 0..8 {
            let z = |bit: u32| if k & bit == 0 { 0.0 } else { -0.0 };
            push(o, Vec3::new(z(1), z(2), z(4)), 0.0, inf);
        }
    }

    // 5. Odd intervals.
    let just_below_one = f32::from_bits(1.0f32.to_bits() - 1);
    let just_above_one = f32::from_bits(1.0f32.to_bits() + 1);
    for &(o, d) in &bases {
        for (tmin, tmax) in [
            (2.0, 1.0),
            (1.0, 0.5),
            (just_above_one, 1.0),
            (1.0, 1.0),
            (0.0, 0.0),
            (0.5, 0.5),
            (-1e30, inf),
            (-1.0, 0.5),
            (0.0, -0.0),
            (-0.0, 0.0),
            (-0.0, -0.0),
            (0.0, just_below_one),
            (0.0, 1.0),
            (just_below_one, just_above_one),
            (just_above_one, inf),
        ] {
            push(o, d, tmin, tmax);
        }
    }
    // From inside, looking both ways: with a negative `tmin` the hits behind the origin count.
    for _ in 0..8 {
        let d = rng.unit_vector();
        push(center, d, -inf, inf);
        push(center, d, -1e30, 0.0);
        push(center, -d, -size, -0.0);
    }

    // 6. Extreme magnitudes.
    for &(o, d) in &bases {
        for scale in [1e30, 1e20, 1e-20, 1e-30, 1e-38, 1e-40, 1e-45] {
            push(o, d * scale, 0.0, inf);
        }
        let u = d.normalize();
        for axis in 0..3 {
            // One dominant component, the other two 1e-20 of it (reciprocals near 1e20).
            let mut lopsided = u * 1e-20;
            lopsided[axis] = u[axis].signum();
            push(o, lopsided, 0.0, inf);
            // One component near the largest float.
            let mut huge = u;
            huge[axis] = f32::MAX.copysign(u[axis]);
            push(o, huge, 0.0, inf);
        }
    }
    out
}

/// A unit axis direction along `axis` with sign `sign`, the other two components `z1`, `z2`
/// (signed zeros).
fn axis_dir(axis: usize, sign: f32, z1: f32, z2: f32) -> Vec3 {
    let mut d = Vec3::ZERO;
    d[axis] = sign;
    d[(axis + 1) % 3] = z1;
    d[(axis + 2) % 3] = z2;
    d
}
