//! The check of all-hits lists ([`raytrail_core::all_hits`]), twice over:
//! - **bit for bit** against a brute force over every triangle with the same watertight test,
//!   the ray framed as the backends frame it: the walk must visit every leaf that holds a hit it
//!   keeps, report each triangle once, and order, merge and cut as the options say;
//! - **against the exact reference**, triangle by triangle ([`exact_hit`]): every triangle the
//!   exact ray hits must be in the list and every listed one must be hit, at a `t` within the
//!   [`Tolerance`], except where the ray passes within the tolerance of the triangle's boundary
//!   (where a float test may decide either way: the neighbour across a shared edge, or both) or
//!   the hit lies within it of the interval's ends.
//!
//! The exact check goes over every triangle for every ray: it is for small scenes.
//!
//! [`check_backend`] is the conformance suite's all-hits case ([`crate::suite::Case::AllHits`]):
//! both checks on a backend's lists ([`Trace::all_hits`]) under every option of [`OPTIONS`].

use crate::exact::filter::{filter, margin, Filtered};
use crate::exact::triangle::exact_hit;
use crate::exact::Tolerance;
use crate::rays::{ray_sets, RaySetSize};
use crate::reference::SerialBackend;
use crate::scenes::{self, NamedScene};
use raytrail_core::all_hits::{AllHits, AllHitsOptions};
use raytrail_core::bvh2::{Bvh2, SahBuilder, SbvhBuilder};
use raytrail_core::geometry::Triangle;
use raytrail_core::intersect::{TriangleTest, Watertight};
use raytrail_core::method::{Bvh2Method, Method, WideMethod};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::traverse::begin_slab;
use raytrail_core::wide::WideTree;
use raytrail_core::{Hit, Ray};
use std::sync::Arc;

/// The triangles of `prepared` by primitive id, in its frame (scaled as it was prepared), from
/// the wide tree the all-hits walk reads.
fn framed_triangles(prepared: &PreparedScene) -> Vec<(u32, Triangle)> {
    let (tree, _) = prepared.query_tree().expect("a scene with a wide tree");
    let (tris, prims) = match tree {
        WideTree::Four(t) => (t.triangles(), t.prims()),
        WideTree::Eight(t) => (t.triangles(), t.prims()),
    };
    let mut out: Vec<(u32, Triangle)> =
        prims.iter().zip(tris).filter(|(&p, _)| p != u32::MAX).map(|(&p, &t)| (p, t)).collect();
    // A triangle a spatial split cut lies in several leaves, the same triangle in each.
    out.sort_by_key(|(p, _)| *p);
    out.dedup_by_key(|(p, _)| *p);
    out
}

/// What the lists of `rays` must be in `prepared` under `options`, by brute force: per ray, the
/// hits and whether the list is cut.
pub fn brute_force(prepared: &PreparedScene, rays: &[Ray], options: &AllHitsOptions) -> Vec<(Vec<Hit>, bool)> {
    let tris = framed_triangles(prepared);
    rays.iter()
        .map(|ray| {
            let framed = prepared.frame_rays(std::slice::from_ref(ray));
            let mut probe = [Hit::MISS];
            if framed.finish(&mut probe) == 1 {
                return (vec![Hit::REFUSED], false);
            }
            let r = framed.rays()[0];
            let mut hits = Vec::new();
            if begin_slab(&r, prepared.scene_scale()).is_some() {
                let per_ray = Watertight::prepare(&r);
                for (prim, t) in &tris {
                    let [a, b, c] = t.v.map(|v| v.to_array());
                    if let Some(h) = Watertight::intersect_in_place(&per_ray, [&a, &b, &c], r.tmin, r.tmax) {
                        hits.push(Hit { t: h.t, prim: *prim, u: h.u, v: h.v });
                    }
                }
            }
            // Ordered, merged and cut in the scene's frame, where the closest hit is decided; then
            // each `t` back in the caller's.
            hits.sort_by(Hit::order);
            if options.merge_equal_t {
                hits.dedup_by(|later, first| later.t == first.t);
            }
            let cut = hits.len() > options.max_hits;
            hits.truncate(options.max_hits);
            for hit in &mut hits {
                framed.finish(std::slice::from_mut(hit));
            }
            (hits, cut)
        })
        .collect()
}

/// Every ray whose list in `got` differs from [`brute_force`]'s, bit for bit in `t`, `prim`,
/// `u` and `v`, or in its truncation flag: `(ray index, what differs)`.
pub fn brute_force_mismatches(
    prepared: &PreparedScene,
    rays: &[Ray],
    options: &AllHitsOptions,
    got: &AllHits,
) -> Vec<(usize, String)> {
    let bits = |h: &Hit| (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits());
    let mut out = Vec::new();
    if got.len() != rays.len() {
        out.push((0, format!("{} lists for {} rays", got.len(), rays.len())));
    }
    for (i, (want, cut)) in brute_force(prepared, rays, options).into_iter().enumerate() {
        let list = got.ray(i).unwrap_or(&[]);
        if list.len() != want.len() || !list.iter().zip(&want).all(|(a, b)| bits(a) == bits(b)) {
            let show = |l: &[Hit]| l.iter().map(|h| format!("({}, {})", h.prim, h.t)).collect::<Vec<_>>().join(" ");
            out.push((i, format!("ray {:?}: expected [{}], got [{}]", rays[i], show(&want), show(list))));
        } else if got.is_truncated(i) != cut {
            out.push((i, format!("truncated: expected {cut}, got {}", got.is_truncated(i))));
        }
    }
    out
}

/// Every disagreement of the complete lists of `got` (rays neither truncated nor refused) with
/// the exact reference over `triangles` (the scene as given, by primitive id), for a scene whose
/// largest coordinate magnitude is `scene_scale`: `(ray index, what disagrees)`. Lists made with
/// [`AllHitsOptions::merge_equal_t`] are not for this check (a merged neighbour is no error).
pub fn exact_mismatches(triangles: &[Triangle], scene_scale: f32, rays: &[Ray], got: &AllHits) -> Vec<(usize, String)> {
    let tol = Tolerance::for_scene(scene_scale);
    let mut out = Vec::new();
    for (i, ray) in rays.iter().enumerate() {
        let list = got.ray(i).unwrap_or(&[]);
        if got.is_truncated(i) || list.iter().any(Hit::is_refused) || !ray.is_traceable() {
            continue;
        }
        for (prim, tri) in triangles.iter().enumerate() {
            let exact = match filter(ray, tri) {
                Filtered::Miss => None,
                Filtered::Hit { .. } | Filtered::Unsure { .. } => exact_hit(ray, tri).map(|t| t.to_f64()),
            };
            let listed = list.iter().find(|h| h.prim == prim as u32).map(|h| f64::from(h.t));
            let near_edge = margin(ray, tri).is_none_or(|m| m.abs() <= tol.delta);
            let near_end = |t: f64| {
                let w = tol.t(ray, tri, t);
                (t - f64::from(ray.tmin)).abs() <= w || (t - f64::from(ray.tmax)).abs() <= w
            };
            let problem = match (exact, listed) {
                (None, None) => None,
                (Some(e), Some(f)) => {
                    (f - e).abs().gt(&tol.t(ray, tri, e)).then(|| format!("triangle {prim}: t {f}, exactly {e}"))
                }
                (Some(e), None) => {
                    (!near_edge && !near_end(e)).then(|| format!("triangle {prim} is hit at t {e} but not listed"))
                }
                (None, Some(f)) => {
                    (!near_edge && !near_end(f)).then(|| format!("triangle {prim} is listed at t {f} but not hit"))
                }
            };
            if let Some(p) = problem {
                out.push((i, format!("ray {ray:?}: {p}")));
            }
        }
    }
    out
}

/// `scene` with tree `bvh` prepared as the query cases check it: the default tracer's 8-wide tree
/// of least node area, which the queries read ([`PreparedScene::query_tree`]), and the BVH2
/// stack walk's layout, which traces the ray sets' closest hits.
pub fn prepared_for_queries(scene: &raytrail_core::scene::Scene, bvh: Bvh2) -> Arc<PreparedScene> {
    let methods = [Method::Bvh2(Bvh2Method::Stack), Method::Wide(WideMethod::BVH8_SAH)];
    Arc::new(PreparedScene::new(scene, bvh, &methods).expect("prepare"))
}

/// Every option lists are checked under: all hits, a limit of two, merged at equal `t`, and merged
/// with a limit of one.
pub const OPTIONS: [AllHitsOptions; 4] = [
    AllHitsOptions { max_hits: usize::MAX, merge_equal_t: false },
    AllHitsOptions { max_hits: 2, merge_equal_t: false },
    AllHitsOptions { max_hits: usize::MAX, merge_equal_t: true },
    AllHitsOptions { max_hits: 1, merge_equal_t: true },
];

/// Rays of the all-hits case per scene: every kind of the suite's ray sets, fewer of each than
/// the methods' cases trace (both checks go over every triangle for every ray).
const RAYS: RaySetSize = RaySetSize { width: 24, height: 18, uniform_count: 256 };

/// The suite's all-hits case on `backend`: the shared-edge grid, the sphereflake (with a SAH and
/// a split tree, whose cut triangles lie in several leaves), the triangle soup and the scene far
/// from the origin, the first three smaller than the methods' cases have them, each prepared
/// with [`prepared_for_queries`]. Under every option of [`OPTIONS`] the lists must be the brute force's bit
/// for bit, and the complete ones must agree with the exact reference; panics with a loud report
/// otherwise, or when the backend has no all-hits query.
pub fn check_backend<B: Trace>(backend: &B) {
    let sah = |s: &NamedScene| SahBuilder::default().build(s.scene.triangles()).expect("SAH build");
    let sbvh = |s: &NamedScene| SbvhBuilder::default().build(s.scene.triangles()).expect("SBVH build");
    let sphereflake = NamedScene::new("sphereflake", scenes::sphereflake(2));
    check_scene(backend, &NamedScene::new("shared_edge_grid", scenes::shared_edge_grid(8)), sah);
    check_scene(backend, &sphereflake, sah);
    let split = sbvh(&sphereflake);
    assert!(split.has_split_references(), "the sphereflake's SBVH tree should cut triangles");
    check_scene(backend, &sphereflake, |_| split);
    check_scene(backend, &NamedScene::new("triangle_soup", scenes::triangle_soup(1500, 7)), sah);
    check_scene(backend, &NamedScene::new("far_from_origin", scenes::far_from_origin()), sah);
}

/// [`check_backend`] on one scene with the tree `build` makes.
fn check_scene<B: Trace>(backend: &B, named: &NamedScene, build: impl FnOnce(&NamedScene) -> Bvh2) {
    let prepared = prepared_for_queries(&named.scene, build(named));
    let serial = SerialBackend;
    let mut closest = |rays: &[Ray]| {
        let mut hits = vec![Hit::MISS; rays.len()];
        serial.trace(&prepared, rays, &TraceOptions::new(Bvh2Method::Stack), &mut hits).expect("serial trace");
        hits
    };
    let rays: Vec<Ray> = ray_sets(&named.scene, RAYS, &mut closest).into_iter().flat_map(|s| s.rays).collect();
    let scene = backend.prepare(prepared.clone()).expect("prepare on the backend");
    for options in &OPTIONS {
        let what = format!("backend {}, scene {}, {options:?}", backend.name(), named.name);
        let lists = backend
            .all_hits(&scene, &rays, options)
            .unwrap_or_else(|e| panic!("NOT CONFORMING: {what}: all hits failed: {e}"));
        // Complete lists of a few hits each at least, so that order, merging and cuts are
        // exercised.
        let (hits, long) = (lists.hits().len(), lists.iter().filter(|l| l.len() > 2).count());
        let complete = *options == OPTIONS[0];
        assert!(!complete || (hits > rays.len() / 4 && long > 0), "{what}: {hits} hits, {long} lists of more than two");
        let wrong = brute_force_mismatches(&prepared, &rays, options, &lists);
        assert!(
            wrong.is_empty(),
            "NOT CONFORMING: {what}: {} of {} rays' lists differ from the brute force's: {:?}",
            wrong.len(),
            rays.len(),
            &wrong[..wrong.len().min(3)]
        );
        // Far from the origin, the adversarial rays' tiny directions put exact distances past
        // f32's range (1e40 and more), which a float list holds as t = inf.
        if complete && named.name != "far_from_origin" {
            let wrong = exact_mismatches(named.scene.triangles(), named.scene.bounds().max_abs(), &rays, &lists);
            assert!(
                wrong.is_empty(),
                "NOT CONFORMING: {what}: {} disagreements with the exact reference: {:?}",
                wrong.len(),
                &wrong[..wrong.len().min(3)]
            );
        }
    }
}
