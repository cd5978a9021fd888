//! Every kd method against the kd stack traversal (same leaves in the same order) and against
//! brute force (same closest hit, bit for bit), through the core alone.

use glam::Vec3;
use raytrail_core::bvh2::NodeRef;
use raytrail_core::geometry::Triangle;
use raytrail_core::intersect::{TriangleTest, Watertight};
use raytrail_core::kd::traverse::packets::packets;
use raytrail_core::kd::traverse::{trace_kd_packet, trace_kd_ray, KdRoot, RestartPolicy, PACKET_WIDTH};
use raytrail_core::kd::{KdBuilder, KdSliceMemory};
use raytrail_core::method::{KdMethod, Query};
use raytrail_core::observe::{Both, Counters, Recorder};
use raytrail_core::{Hit, Ray};

mod common;
use common::{soup, Rng};

/// Axis-aligned quads on a grid: triangles lie in split planes and share edges.
fn boxes(n: usize) -> Vec<Triangle> {
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (i as f32, j as f32);
            for z in [0.0, 2.0, 5.0] {
                let (a, b, c, d) = (
                    Vec3::new(x, y, z),
                    Vec3::new(x + 1.0, y, z),
                    Vec3::new(x + 1.0, y + 1.0, z),
                    Vec3::new(x, y + 1.0, z),
                );
                t.push(Triangle::new(a, b, c));
                t.push(Triangle::new(a, c, d));
            }
            t.push(Triangle::new(Vec3::new(x, y, 0.0), Vec3::new(x, y + 1.0, 0.0), Vec3::new(x, y, 5.0)));
        }
    }
    t
}

fn brute(tris: &[Triangle], ray: &Ray, any: bool) -> Hit {
    let mut best = Hit::MISS;
    if !ray.is_traceable() {
        return best;
    }
    let r = Watertight::prepare(ray);
    for (i, t) in tris.iter().enumerate() {
        let limit = if best.is_hit() { best.t } else { ray.tmax };
        if let Some(h) = Watertight::intersect(&r, t.v[0], t.v[1], t.v[2], ray.tmin, limit) {
            if !best.is_hit() || best.is_beaten_by(h.t, i as u32) {
                best = Hit { t: h.t, prim: i as u32, u: h.u, v: h.v };
            }
        }
    }
    if any {
        return if best.is_hit() { best } else { Hit::MISS };
    }
    best
}

fn rays(tris: &[Triangle], n: usize, seed: u64) -> Vec<Ray> {
    let mut r = Rng(seed);
    let mut out: Vec<Ray> = (0..n)
        .map(|i| {
            let t = &tris[i % tris.len()];
            let target = if i % 3 == 0 { t.v[0] } else { t.centroid() };
            let from = target + (r.v() - 0.5) * 30.0;
            Ray::new(from, target - from, 0.0, f32::INFINITY)
        })
        .collect();
    // Axis-parallel rays with both zero signs, along grid lines.
    for k in 0..40 {
        let (x, y) = ((k % 7) as f32, (k / 7) as f32);
        for (d, o) in [
            (Vec3::new(0.0, 0.0, 1.0), Vec3::new(x, y, -3.0)),
            (Vec3::new(-0.0, 0.0, -1.0), Vec3::new(x, y + 0.5, 9.0)),
            (Vec3::new(1.0, -0.0, 0.0), Vec3::new(-3.0, y, 2.0)),
        ] {
            out.push(Ray::new(o, d, 0.0, f32::INFINITY));
        }
    }
    out
}

fn check(tris: Vec<Triangle>, seed: u64) {
    let tree = KdBuilder::default().build(&tris).unwrap();
    let mem = KdSliceMemory { nodes: tree.nodes(), prims: tree.prims(), triangles: &tris };
    let b = tree.bounds();
    let root = KdRoot {
        lo: b.min,
        hi: b.max,
        scene_scale: b.min.abs().max(b.max.abs()).max_element(),
        max_steps: 1 << 24,
        short_stack: 3,
    };
    let leaves =
        |r: &Recorder| -> Vec<u32> { r.nodes.iter().filter(|n| n.is_leaf()).map(|n: &NodeRef| n.offset()).collect() };
    let rays = rays(&tris, 600, seed);
    for query in [Query::Closest, Query::Any] {
        let any = query == Query::Any;
        let mut stack_leaves = Vec::new();
        let mut inner = [0u64; 4];
        for (i, ray) in rays.iter().enumerate() {
            let expected = brute(&tris, ray, any);
            let mut reference = Vec::new();
            // The packet method alone traces its ray as a packet of one.
            for (k, m) in KdMethod::ALL.into_iter().enumerate() {
                let mut o = Both(Counters::default(), Recorder::default());
                let hit = trace_kd_ray::<_, Watertight, _>(m, &mem, &root, ray, query, &mut o);
                if k < inner.len() {
                    inner[k] += o.0.internal_nodes;
                }
                if any {
                    assert_eq!(hit.is_hit(), expected.is_hit(), "{m} ray {i}");
                } else {
                    assert!(hit.same_as(&expected), "{m} ray {i}: {hit:?} vs brute force {expected:?}");
                }
                if m == KdMethod::Stack {
                    reference = leaves(&o.1);
                } else {
                    assert_eq!(leaves(&o.1), reference, "{m} ray {i} leaves");
                }
            }
            stack_leaves.push(reference);
        }
        // Packets as every backend groups them.
        {
            for group in packets(&rays) {
                let packet: Vec<Ray> = group.iter().map(|&i| rays[i as usize]).collect();
                let mut hits = [Hit::MISS; PACKET_WIDTH];
                let mut obs: [Recorder; PACKET_WIDTH] = Default::default();
                let policy = RestartPolicy::short_stack(3);
                trace_kd_packet::<PACKET_WIDTH, _, Watertight, _>(
                    &mem, &root, &packet, query, policy, &mut hits, &mut obs,
                );
                for (k, &i) in group.iter().enumerate() {
                    let i = i as usize;
                    let expected = brute(&tris, &rays[i], any);
                    if any {
                        assert_eq!(hits[k].is_hit(), expected.is_hit(), "packet ray {i}");
                    } else {
                        assert!(hits[k].same_as(&expected), "packet ray {i}: {:?} vs {expected:?}", hits[k]);
                    }
                    assert_eq!(leaves(&obs[k]), stack_leaves[i], "packet ray {i} leaves");
                }
            }
        }
        // Horn et al.'s trend: restart visits the most interior nodes, push-down fewer, short-stack
        // fewer still, and none fewer than the unbounded stack.
        assert!(inner[1] >= inner[2] && inner[2] >= inner[3] && inner[3] >= inner[0], "{inner:?}");
    }
}

#[test]
fn kd_methods_agree_on_a_soup() {
    check(soup(3000, 3, 1.5), 5);
}

#[test]
fn kd_methods_agree_on_axis_aligned_boxes() {
    check(boxes(12), 6);
}
