//! A slanted sliver met by a grazing ray, where the watertight test's `f32` distance strays.
//!
//! The case comes from Sponza's inside view (primary ray 61503, triangle 9862): a sliver 10.8
//! long and about 0.013 wide, seen along its length. Its `f32` edge functions cancel, and the `t`
//! they weight strays along the sliver's depth range: 1045 ulps off the exact `t`. The test's
//! error bound flags the hit, and the `f64` recomputation must bring `t` within a few ulps, the
//! same bits from the scalar and the four-wide test, and the hit must not depend on a `tmax`
//! that falls between the `f32` and the refined `t` (the traversal order sets `tmax`).

use glam::Vec3;
use raytrail_conformance::exact::triangle::exact_hit;
use raytrail_core::geometry::Triangle;
use raytrail_core::intersect::{TriangleBlock, TriangleHit, TriangleTest, Watertight, REFINE_ULPS};
use raytrail_core::Ray;

fn vec(bits: [u32; 3]) -> Vec3 {
    Vec3::from_array(bits.map(f32::from_bits))
}

fn ray(tmax: f32) -> Ray {
    let o = vec([1005404160, 1078914705, 985860096]);
    let d = vec([1058935439, 1058287974, 1057511017]);
    Ray::new(o, d, 0.0, tmax)
}

fn sliver() -> Triangle {
    Triangle::new(
        vec([1093483616, 1086038078, 1075509673]),
        vec([1005403526, 1086038078, 1075509677]),
        vec([1005403526, 1086059052, 1075543227]),
    )
}

/// `|x − exact|` in ulps of `f32` at `exact`.
fn ulps(x: f32, exact: f64) -> f64 {
    let e = (exact as f32).abs();
    (x as f64 - exact).abs() / (f32::from_bits(e.to_bits() + 1) - e) as f64
}

/// The watertight test's `f32` arithmetic without the refinement: what it answered before.
fn plain_f32_t(ray: &Ray, tri: &Triangle) -> f32 {
    let (o, d) = (ray.origin(), ray.dir());
    // This ray's dominant axis is x, positive: kx = y, ky = z.
    let (kx, ky, kz) = (1, 2, 0);
    let (sx, sy, sz) = (d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
    let [a, b, c] = tri.v.map(|p| p - o);
    let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
    let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
    let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
    let (u, v, w) = (cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax);
    (u * (sz * a[kz]) + v * (sz * b[kz]) + w * (sz * c[kz])) / (u + v + w)
}

fn bits(h: Option<TriangleHit>) -> Option<[u32; 3]> {
    h.map(|h| [h.t, h.u, h.v].map(f32::to_bits))
}

#[test]
fn the_refined_t_is_within_a_few_ulps_where_the_f32_t_strays() {
    let (ray, tri) = (ray(f32::INFINITY), sliver());
    let exact = exact_hit(&ray, &tri).expect("the ray hits the sliver").to_f64();
    let plain = plain_f32_t(&ray, &tri);
    assert!(ulps(plain, exact) > 500.0, "the f32 t is only {} ulps off", ulps(plain, exact));
    assert!(ulps(plain, exact) < REFINE_ULPS as f64 * 8.0, "the case no longer shows what it was chosen for");

    let r = Watertight::prepare(&ray);
    let hit = Watertight::intersect(&r, tri.v[0], tri.v[1], tri.v[2], ray.tmin, ray.tmax).expect("a hit");
    assert!(ulps(hit.t, exact) < 4.0, "refined t {} is {} ulps off {exact}", hit.t, ulps(hit.t, exact));
    assert!(hit.u >= 0.0 && hit.v >= 0.0 && hit.u + hit.v <= 1.0 + 1e-6, "barycentrics {hit:?}");

    // The four-wide test sends the flagged lane to the scalar test: the same bits.
    let block = TriangleBlock::new(&[tri, tri]);
    let four = Watertight::intersect_block(&r, &block, ray.tmin, ray.tmax);
    assert_eq!(bits(four.get(0)), bits(Some(hit)));
    assert_eq!(bits(four.get(1)), bits(Some(hit)));
    assert_eq!(four.mask, 0b11);
}

#[test]
fn a_tmax_between_the_f32_and_the_refined_t_does_not_decide_the_hit() {
    let tri = sliver();
    let free = ray(f32::INFINITY);
    let r = Watertight::prepare(&free);
    let refined = Watertight::intersect(&r, tri.v[0], tri.v[1], tri.v[2], 0.0, f32::INFINITY).expect("a hit");
    let plain = plain_f32_t(&free, &tri);
    assert_ne!(plain, refined.t);
    // A closest hit so far between the two: the answer is the refined t's verdict on it alone.
    let between = f32::from_bits((plain.to_bits() + refined.t.to_bits()) / 2);
    let got = Watertight::intersect(&r, tri.v[0], tri.v[1], tri.v[2], 0.0, between);
    assert_eq!(bits(got), bits((refined.t <= between).then_some(refined)));
    let block = TriangleBlock::new(&[tri]);
    assert_eq!(bits(Watertight::intersect_block(&r, &block, 0.0, between).get(0)), bits(got));
}
