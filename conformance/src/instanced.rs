//! The instanced check: a scene of instances of generated meshes, traced by a backend's methods
//! through [`trace_instanced`], each answer judged against the exact answer of the same
//! triangles flattened into one list ([`flatten`]).
//!
//! Instanced rays are mapped into each mesh's frame and the flattened vertices are mapped into
//! the world, each rounded on its own, so bit-identity with a flat scene is not the rule;
//! agreement with the exact answer within the edge tolerance of [`judge`] is. Masks are checked
//! by leaving an instance out: rays whose mask excludes it must never enter it, and are judged
//! against the flattened triangles of the other instances.

use crate::exact::{judge, ExactScene, Judgement, Tolerance};
use crate::rays::{ray_sets, RaySetSize};
use crate::reference::SerialBackend;
use crate::scenes::{shared_edge_grid, sphereflake, triangle_soup};
use glam::{Affine3A, EulerRot, Quat, Vec3};
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::geometry::Triangle;
use raytrail_core::instance::{trace_instanced, Instance, InstanceHit, InstancedScene, Transform};
use raytrail_core::method::{Bvh2Method, Method, Query, StreamMethod, WideMethod};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::scene::Scene;
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::{Hit, Ray};
use std::sync::Arc;

/// The methods the instanced check runs: the BVH2 stack and hash walks, the wide trees' stack,
/// packet and trail walks and the stream (between them every kind of walk a bottom level can
/// have; `auto` picks among these).
pub const INSTANCED_METHODS: [Method; 7] = [
    Method::Bvh2(Bvh2Method::Stack),
    Method::Bvh2(Bvh2Method::Hash),
    Method::Wide(WideMethod::BVH8),
    Method::Wide(WideMethod::BVH8_SAH),
    Method::Wide(WideMethod::BVH8_SAH_PACKET),
    Method::Wide(WideMethod::BVH4_HASH),
    Method::Stream(StreamMethod::Frustum8),
];

/// Ray set sizes of the instanced check.
pub const INSTANCED_RAYS: RaySetSize = RaySetSize { width: 40, height: 30, uniform_count: 1024 };

/// The meshes and instances of the check: a sphereflake, a triangle soup and a grid of shared
/// edges, placed seven times by moves, rotations, uniform and non-uniform scales and a mirror
/// (a negative determinant flips every triangle's winding), one mesh twice; instance `i` has id
/// `100 + i` and mask bit `i`.
pub fn instanced_case() -> InstancedCase {
    let scenes: Vec<Scene> = vec![sphereflake(2), triangle_soup(1500, 0x1234_5678), shared_edge_grid(12)];
    let meshes = scenes
        .iter()
        .map(|s| {
            let bvh = SahBuilder::default().build(s.triangles()).expect("SAH build");
            Arc::new(PreparedScene::new(s, bvh, &INSTANCED_METHODS).expect("prepare"))
        })
        .collect();
    let place = |scale: Vec3, (x, y, z): (f32, f32, f32), at: Vec3| {
        Transform::from_affine(Affine3A::from_scale_rotation_translation(
            scale,
            Quat::from_euler(EulerRot::XYZ, x, y, z),
            at,
        ))
    };
    let placements = [
        (0, Transform::IDENTITY),
        (0, place(Vec3::splat(0.5), (0.4, 0.0, 1.1), Vec3::new(3.0, 0.5, -1.0))),
        (1, place(Vec3::new(1.0, 2.0, 0.5), (0.0, 0.7, 0.0), Vec3::new(-3.0, 0.0, 0.5))),
        (1, place(Vec3::new(-1.0, 1.0, 1.0), (1.3, -0.2, 0.4), Vec3::new(0.0, 3.0, 0.0))),
        (2, place(Vec3::splat(3.0), (0.0, 0.0, 0.0), Vec3::new(-1.5, -1.5, -2.5))),
        (2, place(Vec3::splat(1.0), (1.57, 0.0, 0.0), Vec3::new(0.0, -2.0, 1.0))),
        (0, place(Vec3::splat(0.25), (0.0, 2.0, 0.3), Vec3::new(1.0, -1.0, 2.0))),
    ];
    let instances = placements
        .iter()
        .enumerate()
        .map(|(i, &(m, t))| Instance::new(m, t).with_id(100 + i as u32).with_mask(1 << i))
        .collect();
    InstancedCase { scenes, meshes, instances }
}

/// An instanced scene as the check takes it.
pub struct InstancedCase {
    /// The meshes as given.
    pub scenes: Vec<Scene>,
    /// The meshes prepared.
    pub meshes: Vec<Arc<PreparedScene>>,
    /// The placements.
    pub instances: Vec<Instance>,
}

/// The triangles of `instances` of `meshes` in the world (each vertex mapped in `f64` and
/// rounded once), in instance order, and per instance the index of its first triangle; the
/// instances `skip` names are left out (their first index is that of the next).
pub fn flatten(meshes: &[Scene], instances: &[Instance], skip: Option<usize>) -> (Vec<Triangle>, Vec<u32>) {
    let (mut flat, mut first) = (Vec::new(), Vec::new());
    for (i, inst) in instances.iter().enumerate() {
        first.push(flat.len() as u32);
        if skip == Some(i) {
            continue;
        }
        let map = |p: Vec3| {
            let w = inst.transform.apply(p.to_array());
            Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32)
        };
        let mesh = &meshes[inst.mesh as usize];
        flat.extend(mesh.triangles().iter().map(|t| Triangle::new(map(t.v[0]), map(t.v[1]), map(t.v[2]))));
    }
    (flat, first)
}

/// Every disagreement of `backend` on `case` with the exact answer of its triangles flattened by
/// the placements `truth` (`case.instances` but where a test plants a wrong one), for each of
/// [`INSTANCED_METHODS`], both queries and every ray set, then once more with each instance
/// masked out in turn (closest hits, the first method): a line per wrong ray, naming the method,
/// the ray set and the ray.
pub fn instanced_mismatches<B: Trace>(backend: &B, case: &InstancedCase, truth: &[Instance]) -> Vec<String> {
    let instances = &case.instances[..];
    let scene = InstancedScene::prepare(backend, &case.meshes, instances).expect("prepare the instances");
    let (flat, first) = flatten(&case.scenes, truth, None);
    let flat_scene = Scene::new(flat.clone()).expect("a flattened scene");
    let serial_flat = {
        let bvh = SahBuilder::default().build(flat_scene.triangles()).expect("SAH build");
        Arc::new(PreparedScene::new(&flat_scene, bvh, &[Method::Bvh2(Bvh2Method::Stack)]).expect("prepare"))
    };
    let mut trace_closest = |rays: &[Ray]| {
        let mut hits = vec![Hit::MISS; rays.len()];
        SerialBackend.trace(&serial_flat, rays, &TraceOptions::new(Bvh2Method::Stack), &mut hits).expect("trace");
        hits
    };
    let sets = ray_sets(&flat_scene, INSTANCED_RAYS, &mut trace_closest);
    let exact = ExactScene::new(flat.clone());
    let tol = Tolerance::for_scene(flat_scene.bounds().max_abs());
    let mut out = Vec::new();
    for set in &sets {
        let answers: Vec<_> = set.rays.iter().map(|r| exact.closest_hit(r)).collect();
        for method in INSTANCED_METHODS {
            for query in Query::ALL {
                let mut hits = vec![InstanceHit::MISS; set.rays.len()];
                let opts = TraceOptions::new(method).query(query);
                trace_instanced(backend, &scene, &set.rays, None, &opts, &mut hits).expect("trace");
                for (i, (ray, h)) in set.rays.iter().zip(&hits).enumerate() {
                    let flat_hit = to_flat(h, &first, instances);
                    let verdict = match query {
                        Query::Closest => judge(ray, &flat, &answers[i], &flat_hit, tol, false),
                        Query::Any => judge_any(ray, &flat, &answers[i], &flat_hit, tol),
                    };
                    if let Judgement::Disagree(why) = verdict {
                        out.push(format!("{method} {query:?} {} ray {i} {ray:?}: {why} (got {h:?})", set.kind.name()));
                    }
                }
            }
        }
    }
    // Masks: every ray excludes instance `k`; it must never be entered, and the answers are
    // those of the other instances' triangles.
    let rays = &sets[0].rays;
    for k in 0..instances.len() {
        let masks = vec![!instances[k].mask; rays.len()];
        let mut hits = vec![InstanceHit::MISS; rays.len()];
        let opts = TraceOptions::new(INSTANCED_METHODS[0]);
        let report = trace_instanced(backend, &scene, rays, Some(&masks), &opts, &mut hits).expect("trace");
        if report.entered[k] != 0 {
            out.push(format!("instance {k} masked out, but {} rays entered it", report.entered[k]));
        }
        let (flat, first) = flatten(&case.scenes, truth, Some(k));
        let exact = ExactScene::new(flat.clone());
        for (i, (ray, h)) in rays.iter().zip(&hits).enumerate() {
            if h.is_hit() && h.index as usize == k {
                out.push(format!("instance {k} masked out, but ray {i} hit it"));
                continue;
            }
            let flat_hit = to_flat(h, &first, instances);
            if let Judgement::Disagree(why) = judge(ray, &flat, &exact.closest_hit(ray), &flat_hit, tol, false) {
                out.push(format!("instance {k} masked out: ray {i} {ray:?}: {why} (got {h:?})"));
            }
        }
    }
    out
}

/// Every closest hit of `hits` (of `rays` through `instances`) that disagrees with the exact
/// answer of the flattened triangles (`flat` and `first` from [`flatten`]) beyond the edge
/// tolerance of [`judge`]: a line per wrong ray.
pub fn closest_disagreements(
    flat: &[Triangle],
    first: &[u32],
    instances: &[Instance],
    rays: &[Ray],
    hits: &[InstanceHit],
) -> Vec<String> {
    let exact = ExactScene::new(flat.to_vec());
    let tol = Tolerance::for_scene(Scene::new(flat.to_vec()).map_or(f32::INFINITY, |s| s.bounds().max_abs()));
    let mut out = Vec::new();
    for (i, (ray, h)) in rays.iter().zip(hits).enumerate() {
        let flat_hit = to_flat(h, first, instances);
        if let Judgement::Disagree(why) = judge(ray, flat, &exact.closest_hit(ray), &flat_hit, tol, false) {
            out.push(format!("ray {i} {ray:?}: {why} (got {h:?})"));
        }
    }
    out
}

/// An instanced answer as a hit on the flattened triangles (`first` from [`flatten`]), checking
/// that it names the instance's own id.
fn to_flat(h: &InstanceHit, first: &[u32], instances: &[Instance]) -> Hit {
    let hit = h.hit();
    if !h.is_hit() {
        return hit;
    }
    match instances.get(h.index as usize) {
        Some(inst) if inst.id == h.instance => Hit { prim: first[h.index as usize] + h.prim, ..hit },
        // A hit naming another instance's id, or none: an impossible primitive, judged wrong.
        _ => Hit { prim: u32::MAX - 2, ..hit },
    }
}

/// An any-hit answer: a hit must be a triangle the ray meets (judged as a closest answer would be
/// at that triangle, without asking that it be the nearest); a miss must be one the closest
/// judgement accepts.
fn judge_any(ray: &Ray, flat: &[Triangle], exact: &crate::exact::ExactAnswer, hit: &Hit, tol: Tolerance) -> Judgement {
    if !hit.is_hit() || hit.is_refused() {
        return judge(ray, flat, exact, hit, tol, false);
    }
    let Some(tri) = flat.get(hit.prim as usize) else {
        return Judgement::Disagree(format!("primitive {} does not exist", hit.prim));
    };
    let alone = crate::exact::closest_hit(ray, std::slice::from_ref(tri));
    let alone_hit = Hit { prim: 0, ..*hit };
    match judge(ray, std::slice::from_ref(tri), &alone, &alone_hit, tol, false) {
        Judgement::Disagree(why) => Judgement::Disagree(format!("any hit on primitive {}: {why}", hit.prim)),
        ok => ok,
    }
}
