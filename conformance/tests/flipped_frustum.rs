//! A stream method whose frustum has one plane facing the wrong way culls boxes its rays enter:
//! the suite's checks (closest hits against the stack method's, and the completeness of the
//! packets' leaf lists) must catch it, whichever of the six planes is flipped.

use raytrail_conformance::check::{check_complete, Context, PrimLeaves};
use raytrail_conformance::rays::{ray_sets, RaySetSize};
use raytrail_conformance::suite::generated_scene;
use raytrail_conformance::SerialBackend;
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::glam::Vec3;
use raytrail_core::intersect::Watertight;
use raytrail_core::method::{Bvh2Method, Method, Query, StreamMethod};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::stream::frustum::NO_AXIS;
use raytrail_core::stream::{trace_stream, Frustum, FrustumCull, FrustumTest, Serial, StreamParams};
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::wide::ReferenceKernel;
use raytrail_core::{Hit, Ray};
use std::sync::Arc;

/// The planes: 0 near, 1 far, then the lower and upper side planes of the two other axes.
const PLANES: usize = 6;

/// The method's frustum test with plane `K` flipped (its kept half-space swapped for the other);
/// `K = PLANES` flips none.
struct Flipped<const K: usize>;

impl<const K: usize> FrustumTest for Flipped<K> {
    fn overlaps(f: &Frustum, lo: Vec3, hi: Vec3) -> bool {
        if f.active == 0 {
            return false;
        }
        if (0..3).any(|i| hi[i] < f.lo[i] || lo[i] > f.hi[i]) {
            return false;
        }
        if f.axis == NO_AXIS {
            return true;
        }
        let a = f.axis as usize;
        let (mut x0, mut x1) = (lo[a], hi[a]);
        // Near keeps x >= near; flipped, x <= near. Far keeps x <= far; flipped, x >= far.
        if K == 0 {
            x1 = x1.min(f.near)
        } else {
            x0 = x0.max(f.near)
        }
        if K == 1 {
            x0 = x0.max(f.far)
        } else {
            x1 = x1.min(f.far)
        }
        if x0 > x1 {
            return false;
        }
        let (s0, s1) = ((x0 - f.near) * f.inv_span, (x1 - f.near) * f.inv_span);
        let at = |k: usize, s: f32| f.near_rect[k] + (f.far_rect[k] - f.near_rect[k]) * s;
        for (side, axis) in [(0, (a + 1) % 3), (2, (a + 2) % 3)] {
            let (lower, upper) = (2 + side, 3 + side);
            // The lower plane keeps points above it, the upper plane points below it.
            let lower_culls = if K == lower {
                lo[axis] > at(side, s0).max(at(side, s1))
            } else {
                hi[axis] < at(side, s0).min(at(side, s1))
            };
            let upper_culls = if K == upper {
                hi[axis] < at(side + 1, s0).min(at(side + 1, s1))
            } else {
                lo[axis] > at(side + 1, s0).max(at(side + 1, s1))
            };
            if lower_culls || upper_culls {
                return false;
            }
        }
        true
    }
}

/// Rays on which the stream method with plane `K` flipped parts from the stack method's closest
/// hit, or whose packet's leaf list lacks the leaf of that hit, over the sphereflake's ray sets.
fn caught<const K: usize>() -> usize {
    let named = generated_scene("sphereflake");
    let bvh = SahBuilder::default().build(named.scene.triangles()).expect("build");
    let methods = [Method::Stream(StreamMethod::Frustum8), Bvh2Method::Stack.into()];
    let prepared = Arc::new(PreparedScene::new(&named.scene, bvh, &methods).expect("prepare"));
    let serial_scene = SerialBackend.prepare(prepared.clone()).expect("prepare");
    let mut closest = |rays: &[Ray]| {
        let mut hits = vec![Hit::MISS; rays.len()];
        SerialBackend.trace(&serial_scene, rays, &TraceOptions::new(Bvh2Method::Stack), &mut hits).expect("trace");
        hits
    };
    let sets = ray_sets(&named.scene, RaySetSize { width: 48, height: 36, uniform_count: 2048 }, &mut closest);
    let scene = prepared.stream_scene(StreamMethod::Frustum8).expect("stream scene");
    let leaves = PrimLeaves::new(&prepared.bvh);
    let mut found = 0;
    for set in &sets {
        let reference = closest(&set.rays);
        let mut hits = vec![Hit::MISS; set.rays.len()];
        // In the scene's frame, as every backend traces (far origins moved up to the scene).
        let framed = prepared.frame_rays(&set.rays);
        let out = trace_stream::<_, Flipped<K>, Watertight, ReferenceKernel>(
            &Serial,
            &scene,
            framed.rays(),
            &mut hits,
            Query::Closest,
            &StreamParams::default(),
            false,
            true,
        )
        .expect("trace");
        framed.finish(&mut hits);
        found += reference.iter().zip(&hits).filter(|(e, g)| !e.same_as(g)).count();
        let ctx = Context { scene: &named.name, ray_set: set.kind.name(), backend: "flipped-frustum" };
        let enumerations = out.enumerations.unwrap_or_default();
        let method = Method::Stream(StreamMethod::Frustum8);
        found += check_complete(ctx, &set.rays, method, &reference, &enumerations, &leaves).len();
    }
    found
}

#[test]
fn every_flipped_plane_is_caught() {
    assert!(caught::<0>() > 0, "the near plane flipped passed");
    assert!(caught::<1>() > 0, "the far plane flipped passed");
    assert!(caught::<2>() > 0, "the first lower side plane flipped passed");
    assert!(caught::<3>() > 0, "the first upper side plane flipped passed");
    assert!(caught::<4>() > 0, "the second lower side plane flipped passed");
    assert!(caught::<5>() > 0, "the second upper side plane flipped passed");
}

#[test]
fn the_intact_frustum_passes_the_same_check() {
    assert_eq!(caught::<PLANES>(), 0);
    // And the copy above is the method's test where nothing is flipped.
    let f = Frustum::build([Ray::new(Vec3::ZERO, Vec3::new(1.0, 0.2, 0.1), 0.0, 10.0)].iter(), &bounds(), 2.0);
    for i in 0..1000 {
        let c = Vec3::new((i % 10) as f32, ((i / 10) % 10) as f32 * 0.2 - 1.0, (i / 100) as f32 * 0.2 - 1.0);
        let (lo, hi) = (c - 0.05, c + 0.05);
        assert_eq!(Flipped::<PLANES>::overlaps(&f, lo, hi), FrustumCull::overlaps(&f, lo, hi), "{lo} {hi}");
    }
}

fn bounds() -> raytrail_core::Aabb {
    raytrail_core::Aabb::new(Vec3::splat(-2.0), Vec3::splat(10.0))
}
