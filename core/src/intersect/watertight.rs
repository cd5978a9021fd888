use super::refine::{needs_refine, refine};
use super::{BlockHits, TriangleBlock, TriangleHit, TriangleTest};
use crate::Ray;
use glam::{BVec3A, Vec3, Vec3A, Vec3Swizzles};

/// The watertight ray/triangle test of Woop, Benthin and Wald (2013), the default.
///
/// The ray is sheared so it runs along +z; edge functions are evaluated in 2D and recomputed in
/// `f64` when one is zero or too small to trust ([`TINY_EDGE`]), so that a ray through a shared
/// edge or vertex hits exactly one of the triangles sharing it (no cracks, no double hits).
/// Backfaces are not culled. Where a first-order bound says the `f32` distance may be more than
/// [`REFINE_ULPS`](super::REFINE_ULPS) ulps off (slanted slivers), `t` and the barycentrics are
/// recomputed in `f64`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Watertight;

/// Per-ray constants of the watertight test.
#[derive(Clone, Copy, Debug)]
pub struct ShearedRay {
    /// The origin's coordinates in the permuted order `o[kx], o[ky], o[kz]`.
    origin: [f32; 3],
    /// Axis permutation: `kx`, `ky`, `kz`, with `kz` the dominant direction axis.
    k: [usize; 3],
    /// Shear constants `dx/dz`, `dy/dz`, `1/dz`.
    s: [f32; 3],
    /// The direction in the permuted order, for the `f64` recomputation.
    d: [f32; 3],
}

impl ShearedRay {
    /// The origin's coordinates in the ray's axis order (`o[kx], o[ky], o[kz]`).
    #[inline(always)]
    pub fn origin(&self) -> [f32; 3] {
        self.origin
    }

    /// The axis order `kx, ky, kz`: `kz` the dominant direction axis, `kx, ky` the other two in
    /// the order that keeps the winding.
    #[inline(always)]
    pub fn axes(&self) -> [usize; 3] {
        self.k
    }

    /// The shear constants `dx/dz, dy/dz, 1/dz` (in the ray's axis order).
    #[inline(always)]
    pub fn shear(&self) -> [f32; 3] {
        self.s
    }
}

impl TriangleTest for Watertight {
    type PerRay = ShearedRay;
    const NAME: &'static str = "watertight";

    #[inline]
    fn prepare(ray: &Ray) -> ShearedRay {
        // The permutation by lane selects rather than branches: over scattered directions the
        // branches mispredicted about every other ray, and indexing by the chosen axis went
        // through memory.
        let (d, o) = (Vec3A::from_array(ray.dir), Vec3A::from_array(ray.origin));
        let a = d.abs();
        // Dominant axis; ties go to the lower axis so every backend picks the same one.
        let x_dominant = (a.x >= a.y) & (a.x >= a.z);
        let y_dominant = !x_dominant & (a.y >= a.z);
        // The rotation that puts the dominant axis last: (y, z, x), (z, x, y) or (x, y, z).
        let (on_x, on_y) = (BVec3A::splat(x_dominant), BVec3A::splat(y_dominant));
        let rotate = |v: Vec3A| Vec3A::select(on_x, v.yzx(), Vec3A::select(on_y, v.zxy(), v));
        let (d, o) = (rotate(d), rotate(o));
        // Swapping keeps the winding, so the sign of the determinant keeps its meaning.
        let negative = d.z < 0.0;
        let swap = |v: Vec3A| Vec3A::select(BVec3A::splat(negative), v.yxz(), v);
        let (d, o) = (swap(d), swap(o));
        let kz = if x_dominant { 0 } else { 2 - usize::from(y_dominant) };
        let (kx, ky) = ([1, 2, 0][kz], [2, 0, 1][kz]);
        let (kx, ky) = if negative { (ky, kx) } else { (kx, ky) };
        // `dx/dz, dy/dz, 1/dz` as one 4-wide division where SIMD is available (IEEE per lane).
        let s = d.with_z(1.0) / Vec3A::splat(d.z);
        ShearedRay { origin: o.to_array(), k: [kx, ky, kz], s: s.to_array(), d: d.to_array() }
    }

    #[inline(always)]
    fn sheared(r: &ShearedRay) -> Option<&ShearedRay> {
        Some(r)
    }

    #[inline(always)]
    fn intersect(r: &ShearedRay, a: Vec3, b: Vec3, c: Vec3, tmin: f32, tmax: f32) -> Option<TriangleHit> {
        Self::intersect_in_place(r, [a.as_ref(), b.as_ref(), c.as_ref()], tmin, tmax)
    }

    /// The test proper. Coordinates are picked by the ray's permutation straight from where the
    /// vertices are stored: an index into values held in registers costs a chain of branches or a
    /// trip through memory per coordinate.
    #[inline(always)]
    fn intersect_in_place(r: &ShearedRay, v: [&[f32; 3]; 3], tmin: f32, tmax: f32) -> Option<TriangleHit> {
        let vertices = v;
        let [kx, ky, kz] = r.k;
        let [ox, oy, oz] = r.origin;
        let [sx, sy, sz] = r.s;
        // Each vertex relative to the origin, in ray-space axis order (the same subtractions as
        // `v - origin` followed by the permutation).
        let [a, b, c] = v.map(|p| [p[kx] - ox, p[ky] - oy, p[kz] - oz]);
        let ax = a[0] - sx * a[2];
        let ay = a[1] - sy * a[2];
        let bx = b[0] - sx * b[2];
        let by = b[1] - sy * b[2];
        let cx = c[0] - sx * c[2];
        let cy = c[1] - sy * c[2];
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        // Whether the first-order error bound applies (not to rescaled edge functions).
        let mut bounded = true;
        if is_tiny(u) || is_tiny(v) || is_tiny(w) {
            let exact = exact_edges([ax, ay], [bx, by], [cx, cy]);
            if mixed_signs(exact[0], exact[1], exact[2]) {
                return None;
            }
            let rescaled;
            ([u, v, w], rescaled) = narrow_edges(exact);
            bounded = !rescaled;
        }
        if mixed_signs(u, v, w) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let az = sz * a[2];
        let bz = sz * b[2];
        let cz = sz * c[2];
        let t = (u * az + v * bz + w * cz) / det;
        // A `t` that overflowed (directions near the float limits) is no hit.
        if !t.is_finite() || t < tmin {
            return None;
        }
        let mut hit = TriangleHit { t, u: v / det, v: w / det };
        // Decided before `tmax` is looked at: `tmax` is the closest hit so far, which depends on
        // the traversal order, and a refined `t` may cross it either way.
        if bounded && needs_refine([a, b, c], [[ax, ay], [bx, by], [cx, cy]], [az, bz, cz], t, det) {
            if let Some((t, u, v)) = refine(r.origin, r.d, r.k, vertices) {
                hit = TriangleHit { t, u, v };
            }
            if !hit.t.is_finite() || hit.t < tmin {
                return None;
            }
        }
        if hit.t > tmax {
            return None;
        }
        Some(hit)
    }

    /// Four triangles at once (SSE on x86_64), each lane the scalar test's operations in its
    /// order, so every answer is [`Watertight::intersect_in_place`]'s bit for bit; a lane with a
    /// zero edge function, or one the error bound flags for the `f64` recomputation, takes the
    /// scalar test.
    #[inline(always)]
    fn intersect_block(r: &ShearedRay, block: &TriangleBlock, tmin: f32, tmax: f32) -> BlockHits {
        #[cfg(target_arch = "x86_64")]
        return sse::intersect_block(r, block, tmin, tmax);
        #[cfg(not(target_arch = "x86_64"))]
        {
            let mut out = BlockHits::NONE;
            for lane in 0..super::BLOCK {
                let [a, b, c] = block.lane(lane);
                out.set(lane, Self::intersect_in_place(r, [&a, &b, &c], tmin, tmax));
            }
            out
        }
    }
}

/// Edge functions below this magnitude are recomputed in `f64` (`exact_edges`), as exact zeros
/// are in Woop, Benthin & Wald 2013. Below it an `f32` product may have underflowed (gradually on
/// the CPU, flushed to zero on many GPUs) by more than a rounding error of the edge function, and
/// its sign can be wrong: in a unit-size scene with vertices near `1e-37` (a fuzzed scene of
/// coordinates `1e-1` to `1e36`, scaled) a ray passing outside a triangle hit it. At `2^-100` a
/// flushed product's error, at most `2^-126`, stays below half an ulp of the function.
pub const TINY_EDGE: f32 = f32::from_bits((127 - 100) << 23); // 2^-100

/// The step by which `narrow_edges` scales tiny `f64` edge functions up (and `1 / EDGE_STEP`
/// the magnitude it scales them to at least).
pub const EDGE_STEP: f32 = 18_446_744_073_709_551_616.0; // 2^64

/// Whether an `f32` edge function is too small for its sign to be trusted ([`TINY_EDGE`]).
#[inline(always)]
fn is_tiny(x: f32) -> bool {
    x.abs() < TINY_EDGE
}

/// The `f64` edge functions as `f32`s, first scaled by a power of two that brings the largest to
/// at least `1 / EDGE_STEP` where it is smaller, and whether they were scaled. `t` and the
/// barycentrics are ratios of the three, so a common factor cancels; narrowed as they are, edge
/// functions below the `f32` range turned into zeros and a ray through a triangle of tiny
/// features missed it with `det = 0`. A nonzero one is at least `2^-298` (a difference of products
/// of `f32`s), so four steps suffice.
#[inline(never)]
fn narrow_edges(e: [f64; 3]) -> ([f32; 3], bool) {
    let (step, floor) = (f64::from(EDGE_STEP), 1.0 / f64::from(EDGE_STEP));
    let largest = e[0].abs().max(e[1].abs()).max(e[2].abs());
    if largest >= floor || largest == 0.0 {
        return (e.map(|x| x as f32), false);
    }
    let (mut e, mut largest) = (e, largest);
    while largest < floor {
        e = e.map(|x| x * step);
        largest *= step;
    }
    (e.map(|x| x as f32), true)
}

/// The edge functions `u, v, w` of the sheared vertices in `f64`, where an `f32` one is tiny
/// ([`TINY_EDGE`]): each product of two `f32`s is exact in `f64`, so every sign is that of the
/// exact edge function of these coordinates (the fallback of Woop, Benthin & Wald 2013 that keeps
/// shared edges and vertices watertight).
#[inline(always)]
fn exact_edges(a: [f32; 2], b: [f32; 2], c: [f32; 2]) -> [f64; 3] {
    let f = |p: [f32; 2], q: [f32; 2]| f64::from(p[0]) * f64::from(q[1]) - f64::from(p[1]) * f64::from(q[0]);
    [f(c, b), f(a, c), f(b, a)]
}

/// Whether the edge functions have both signs (the ray passes outside the triangle), in `f32` or
/// in `f64`. The fallback's `f64` edges are tested before they are narrowed to `f32`: an edge
/// function below the `f32` range (vertices within about `1e-23` of the ray in a unit-size scene)
/// narrows to a zero and loses its sign, and a ray outside two triangles then hit them both at a
/// wrong `t`.
#[inline(always)]
fn mixed_signs<F: PartialOrd + From<f32>>(u: F, v: F, w: F) -> bool {
    let zero = F::from(0.0);
    (u < zero || v < zero || w < zero) && (u > zero || v > zero || w > zero)
}

/// The SSE path of [`Watertight::intersect_block`] (SSE2 is part of the x86_64 baseline).
#[cfg(target_arch = "x86_64")]
mod sse {
    use super::super::REFINE_SCALE;
    use super::{BlockHits, ShearedRay, TriangleBlock, TriangleTest, Watertight, TINY_EDGE};
    use core::arch::x86_64::{
        __m128, _mm_add_ps, _mm_and_ps, _mm_andnot_ps, _mm_cmpeq_ps, _mm_cmpgt_ps, _mm_cmplt_ps, _mm_cmpngt_ps,
        _mm_cmpnlt_ps, _mm_div_ps, _mm_loadu_ps, _mm_movemask_ps, _mm_mul_ps, _mm_or_ps, _mm_set1_ps, _mm_storeu_ps,
        _mm_sub_ps,
    };

    #[inline(always)]
    #[allow(unused_unsafe)] // SSE2 intrinsics are safe to call from Rust 1.87 on; rust-version is older.
    pub(super) fn intersect_block(r: &ShearedRay, block: &TriangleBlock, tmin: f32, tmax: f32) -> BlockHits {
        let [kx, ky, kz] = r.k;
        let [ox, oy, oz] = r.origin;
        let [sx, sy, sz] = r.s;
        // SAFETY: SSE2 is part of the x86_64 baseline; loads and stores are of four-float arrays.
        let (ok, t, u, v, slow) = unsafe {
            let splat = _mm_set1_ps;
            let load = |a: &[f32; 4]| _mm_loadu_ps(a.as_ptr());
            let rel = |vertex: usize| {
                let p = &block.v[vertex];
                (
                    _mm_sub_ps(load(&p[kx]), splat(ox)),
                    _mm_sub_ps(load(&p[ky]), splat(oy)),
                    _mm_sub_ps(load(&p[kz]), splat(oz)),
                )
            };
            let ((a0, a1, a2), (b0, b1, b2), (c0, c1, c2)) = (rel(0), rel(1), rel(2));
            let (sxv, syv, szv) = (splat(sx), splat(sy), splat(sz));
            let ax = _mm_sub_ps(a0, _mm_mul_ps(sxv, a2));
            let ay = _mm_sub_ps(a1, _mm_mul_ps(syv, a2));
            let bx = _mm_sub_ps(b0, _mm_mul_ps(sxv, b2));
            let by = _mm_sub_ps(b1, _mm_mul_ps(syv, b2));
            let cx = _mm_sub_ps(c0, _mm_mul_ps(sxv, c2));
            let cy = _mm_sub_ps(c1, _mm_mul_ps(syv, c2));
            let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
            let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
            let w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
            let z = splat(0.0);
            let tiny = |x: __m128| _mm_cmplt_ps(_mm_andnot_ps(splat(-0.0), x), splat(TINY_EDGE));
            let zero = _mm_or_ps(_mm_or_ps(tiny(u), tiny(v)), tiny(w));
            let neg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(u, z), _mm_cmplt_ps(v, z)), _mm_cmplt_ps(w, z));
            let pos = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(u, z), _mm_cmpgt_ps(v, z)), _mm_cmpgt_ps(w, z));
            let det = _mm_add_ps(_mm_add_ps(u, v), w);
            let az = _mm_mul_ps(szv, a2);
            let bz = _mm_mul_ps(szv, b2);
            let cz = _mm_mul_ps(szv, c2);
            let t = _mm_div_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(u, az), _mm_mul_ps(v, bz)), _mm_mul_ps(w, cz)), det);
            // `!t.is_finite() || t < tmin || t > tmax` rejects: NaN fails `|t| < inf`.
            let abs_t = _mm_andnot_ps(splat(-0.0), t);
            let finite = _mm_cmplt_ps(abs_t, splat(f32::INFINITY));
            let det_ok = _mm_andnot_ps(_mm_cmpeq_ps(det, z), _mm_cmpeq_ps(z, z));
            // Hit at a `t` past `tmin`: what the error bound screens, whatever `tmax` is.
            let ahead = _mm_and_ps(
                _mm_andnot_ps(_mm_and_ps(neg, pos), det_ok),
                _mm_and_ps(finite, _mm_cmpnlt_ps(t, splat(tmin))),
            );
            let ok = _mm_and_ps(ahead, _mm_cmpngt_ps(t, splat(tmax)));
            // Lanes with a tiny edge function take the scalar test.
            let zero = _mm_movemask_ps(zero) as u32;
            // The bound only where a lane hits (rare among blocks), so a block of misses pays
            // one branch for it.
            let mut slow = zero;
            let screened = _mm_movemask_ps(ahead) as u32 & !zero;
            if screened != 0 {
                let abs = |x: __m128| _mm_andnot_ps(splat(-0.0), x);
                let m = |p0: __m128, p1: __m128, p2: __m128| {
                    _mm_add_ps(_mm_add_ps(abs(p0), abs(p1)), _mm_add_ps(abs(p2), abs(p2)))
                };
                let (ma, mb, mc) = (m(a0, a1, a2), m(b0, b1, b2), m(c0, c1, c2));
                let (sa, sb, sc) =
                    (_mm_add_ps(abs(ax), abs(ay)), _mm_add_ps(abs(bx), abs(by)), _mm_add_ps(abs(cx), abs(cy)));
                let e = |mp: __m128, sq: __m128, mq: __m128, sp: __m128| {
                    _mm_add_ps(_mm_add_ps(_mm_mul_ps(mp, sq), _mm_mul_ps(mq, sp)), _mm_mul_ps(sp, sq))
                };
                let (eu, ev, ew) = (e(mb, sc, mc, sb), e(mc, sa, ma, sc), e(ma, sb, mb, sa));
                let dz = |zz: __m128| abs(_mm_sub_ps(zz, t));
                let lhs =
                    _mm_add_ps(_mm_add_ps(_mm_mul_ps(eu, dz(az)), _mm_mul_ps(ev, dz(bz))), _mm_mul_ps(ew, dz(cz)));
                let rhs = _mm_mul_ps(splat(REFINE_SCALE), abs(_mm_mul_ps(t, det)));
                slow |= _mm_movemask_ps(_mm_cmpgt_ps(lhs, rhs)) as u32 & screened;
            }
            let store = |x: __m128| {
                let mut out = [0.0f32; 4];
                _mm_storeu_ps(out.as_mut_ptr(), x);
                out
            };
            (_mm_movemask_ps(ok) as u32, store(t), store(_mm_div_ps(v, det)), store(_mm_div_ps(w, det)), slow)
        };
        let mut out = BlockHits { mask: ok & !slow, t, u, v };
        // A zero edge function or a flagged hit (rare): the scalar test, with its f64
        // recomputations. The hit lanes are left as a mask, so the caller branches on hits rather
        // than on each lane.
        let mut z = slow;
        while z != 0 {
            let lane = z.trailing_zeros() as usize;
            let [a, b, c] = block.lane(lane);
            out.set(lane, Watertight::intersect_in_place(r, [&a, &b, &c], tmin, tmax));
            z &= z - 1;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Triangle;
    use crate::intersect::test_values::Rng;
    use alloc::vec::Vec;

    fn shoot(o: Vec3, d: Vec3, tri: [Vec3; 3]) -> Option<TriangleHit> {
        let r = Watertight::prepare(&Ray::new(o, d, 0.0, f32::INFINITY));
        Watertight::intersect(&r, tri[0], tri[1], tri[2], 0.0, f32::INFINITY)
    }

    /// Vertices within about `1e-25` of a ray whose direction is `1e-25` off an axis (a fuzzed
    /// scene, scaled to unit size): the `f32` edge functions underflow to zeros, and their `f64`
    /// recomputation, narrowed to `f32`, flushed a negative one to `-0.0`. Both triangles were
    /// then hit at `t = 0`, where the exact answer misses both (their plane crossings lie outside
    /// them) and a wide tree, culling the second one's box by its entry at `t = 0.84`, answered
    /// another triangle than the binary tree.
    #[test]
    fn an_edge_function_below_the_f32_range_keeps_its_sign() {
        let v = |b: [u32; 3]| Vec3::from_array(b.map(f32::from_bits));
        let o = v([0x1652_5252, 0x82be_be52, 0x82be_bebe]);
        let d = v([0x82be_bebe, 0x3f7b_7b7b, 0x167b_7b7b]);
        let near = [
            [
                v([0x82be_bebe, 0x3f7b_7b7b, 0x167b_7b7b]),
                v([0x1652_5252; 3]),
                v([0x1652_5252, 0x1652_5252, 0x1e52_5252]),
            ],
            [
                v([0x1652_5252; 3]),
                v([0x1652_5252, 0x3f7b_7b7b, 0x3f5b_7b7b]),
                v([0x827b_7b7b, 0x82be_bebe, 0x92ce_cece]),
            ],
        ];
        let r = Watertight::prepare(&Ray::new(o, d, -0.37, f32::INFINITY));
        for [a, b, c] in near {
            assert_eq!(Watertight::intersect(&r, a, b, c, -0.37, f32::INFINITY), None, "{a} {b} {c}");
        }
    }

    /// A fuzzed scene of coordinates from `0.37` to `2e36`, scaled to unit size: vertices near
    /// `1e-37` and `1e-25` around a ray along `y`, where every `f32` edge function's products
    /// underflow. The zero one went to the `f64` fallback, but the narrowed results were
    /// subnormal, and the triangle was hit at `t = 0` where its exact crossing lies at
    /// `t = 18697088683.79` (computed in rationals), far past `tmax`.
    #[test]
    fn edge_functions_below_the_f32_range_keep_their_ratios() {
        let v = |b: [u32; 3]| Vec3::from_array(b.map(f32::from_bits));
        let d = v([0x04c1_4100, 0x24c1_4140, 0x04c1_4141]);
        let [a, b, c] = [
            v([0x823e_bebe, 0x3efb_7b7b, 0x15fb_7b7b]),
            v([0x15d2_5252; 3]),
            v([0x15d2_5252, 0x15d2_5252, 0x1dd2_5252]),
        ];
        let tmax = 12.078_431;
        let r = Watertight::prepare(&Ray::new(Vec3::ZERO, d, 0.0, tmax));
        assert_eq!(Watertight::intersect(&r, a, b, c, 0.0, tmax), None);
        let hit = Watertight::intersect(&r, a, b, c, 0.0, f32::INFINITY).expect("the line crosses the triangle");
        let exact = 18_697_088_683.79f64;
        assert!((f64::from(hit.t) - exact).abs() < 1e-6 * exact, "t = {} against {exact}", hit.t);
    }

    #[test]
    fn hits_center_with_barycentrics() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let h = shoot(Vec3::new(0.25, 0.25, 1.0), Vec3::NEG_Z, tri).unwrap();
        assert_eq!(h.t, 1.0);
        assert!((h.u - 0.25).abs() < 1e-6 && (h.v - 0.25).abs() < 1e-6);
        // Backface: same triangle from below.
        assert_eq!(shoot(Vec3::new(0.25, 0.25, -1.0), Vec3::Z, tri).unwrap().t, 1.0);
    }

    #[test]
    fn no_crack_along_a_shared_edge() {
        // Two triangles share the diagonal of the unit square; oblique rays aimed at the diagonal.
        let t0 = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)];
        let t1 = [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        for i in 1..1000 {
            let s = i as f32 / 1000.0;
            let d = Vec3::new(0.013 * s, -0.007, -1.0);
            let o = Vec3::new(s, s, 0.0) - 3.0 * d;
            let hits = shoot(o, d, t0).is_some() as u32 + shoot(o, d, t1).is_some() as u32;
            assert!(hits >= 1, "crack at s = {s}");
        }
    }

    #[test]
    fn misses_outside_and_respects_interval() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(shoot(Vec3::new(0.75, 0.75, 1.0), Vec3::NEG_Z, tri).is_none());
        let r = Watertight::prepare(&Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z, 0.0, 0.5));
        assert!(Watertight::intersect(&r, tri[0], tri[1], tri[2], 0.0, 0.5).is_none());
    }

    /// The test as first written (on `Vec3`s, `v - origin` then the permutation): the reference
    /// that the in-place reads must match bit for bit.
    fn reference(ray: &Ray, a: Vec3, b: Vec3, c: Vec3) -> Option<TriangleHit> {
        let d = ray.dir();
        let m = d.abs();
        let kz = if m.x >= m.y && m.x >= m.z {
            0
        } else if m.y >= m.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if d[kz] < 0.0 {
            core::mem::swap(&mut kx, &mut ky);
        }
        let (sx, sy, sz) = (d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
        let vertices = [a.to_array(), b.to_array(), c.to_array()];
        let (a, b, c) = (a - ray.origin(), b - ray.origin(), c - ray.origin());
        let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
        let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
        let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
        let (mut u, mut v, mut w) = (cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax);
        let mut bounded = true;
        if u.abs() < TINY_EDGE || v.abs() < TINY_EDGE || w.abs() < TINY_EDGE {
            let [u64, v64, w64] = exact_edges([ax, ay], [bx, by], [cx, cy]);
            if mixed_signs(u64, v64, w64) {
                return None;
            }
            let rescaled;
            ([u, v, w], rescaled) = narrow_edges([u64, v64, w64]);
            bounded = !rescaled;
        }
        if mixed_signs(u, v, w) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t = (u * (sz * a[kz]) + v * (sz * b[kz]) + w * (sz * c[kz])) / det;
        if !t.is_finite() || t < ray.tmin {
            return None;
        }
        let mut hit = TriangleHit { t, u: v / det, v: w / det };
        let k = [kx, ky, kz];
        let rel = [a, b, c].map(|p| k.map(|i| p[i]));
        let xy = [[ax, ay], [bx, by], [cx, cy]];
        if bounded && needs_refine(rel, xy, [sz * a[kz], sz * b[kz], sz * c[kz]], t, det) {
            let o = ray.origin();
            let [p, q, r] = &vertices;
            if let Some((t, u, v)) = refine(k.map(|i| o[i]), k.map(|i| d[i]), k, [p, q, r]) {
                hit = TriangleHit { t, u, v };
            }
            if !hit.t.is_finite() || hit.t < ray.tmin {
                return None;
            }
        }
        (hit.t <= ray.tmax).then_some(hit)
    }

    #[test]
    fn matches_the_reference_bit_for_bit() {
        // Small integer grids make exact zeros (edges and vertices hit dead on) common.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % 9) as f32 - 4.0 + if state & 1 << 40 != 0 { 0.0 } else { 0.37 }
        };
        let (mut hits, mut per_k) = (0, [0; 3]);
        for _ in 0..100_000 {
            let mut v = || Vec3::new(next(), next(), next());
            let (o, d, a, b, c) = (v(), v(), v(), v(), v());
            if d == Vec3::ZERO {
                continue;
            }
            let ray = Ray::new(o, d, 0.0, f32::INFINITY);
            let r = Watertight::prepare(&ray);
            per_k[r.k[2]] += 1;
            let fast = Watertight::intersect(&r, a, b, c, ray.tmin, ray.tmax);
            let slow = reference(&ray, a, b, c);
            let bits = |h: Option<TriangleHit>| h.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits()));
            assert_eq!(bits(fast), bits(slow), "ray {ray:?}, triangle {a} {b} {c}");
            hits += fast.is_some() as u32;
        }
        assert!(hits > 1000 && per_k.iter().all(|&n| n > 1000), "{hits} hits, permutations {per_k:?}");
    }

    #[test]
    fn four_at_once_equals_one_at_a_time_bit_for_bit() {
        let mut rng = Rng(0x5851_f42d_4c95_7f2d);
        let same = |a: Option<TriangleHit>, b: Option<TriangleHit>| match (a, b) {
            (None, None) => true,
            (Some(a), Some(b)) => [a.t, a.u, a.v].map(f32::to_bits) == [b.t, b.u, b.v].map(f32::to_bits),
            _ => false,
        };
        let (mut hits, mut fallbacks) = (0, 0);
        for i in 0..100_000 {
            let (ray, _) = rng.ray_and_slab();
            if !ray.is_traceable() {
                continue;
            }
            let r = Watertight::prepare(&ray);
            // Shared vertices and edges among the lanes, as in a mesh, so zero edge functions come up.
            let pool: [Vec3; 4] = core::array::from_fn(|_| {
                let mut v = || rng.adversarial();
                Vec3::new(v(), v(), v())
            });
            let tris: Vec<Triangle> = (0..1 + i % 4)
                .map(|k| Triangle::new(pool[k % 4], pool[(k + 1) % 4], pool[(k + 2 + (i / 4) % 2) % 4]))
                .collect();
            let block = TriangleBlock::new(&tris);
            let got = Watertight::intersect_block(&r, &block, ray.tmin, ray.tmax);
            for lane in 0..4 {
                let g = got.get(lane);
                let [a, b, c] = block.lane(lane);
                let want = Watertight::intersect_in_place(&r, [&a, &b, &c], ray.tmin, ray.tmax);
                assert!(same(g, want), "lane {lane} of {tris:?}, {ray:?}: {g:?} != {want:?}");
                hits += usize::from(want.is_some());
                if lane < tris.len() {
                    let (ax, ay) = (a[r.k[0]] - r.origin[0], a[r.k[1]] - r.origin[1]);
                    fallbacks += usize::from(ax == 0.0 || ay == 0.0);
                }
            }
        }
        assert!(hits > 1_000, "only {hits} hits");
        assert!(fallbacks > 100, "only {fallbacks} lanes near the fallback");
    }
}
