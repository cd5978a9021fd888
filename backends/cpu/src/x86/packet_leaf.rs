//! A wide packet's leaf with the rays in the lanes: each triangle of the leaf against eight rays of
//! the packet per AVX2 operation, where the single-ray test takes four triangles against one ray.
//! A leaf that a packet reaches is reached by nine rays or more (fewer are handed over), so a
//! triangle's loads and the test's chain of latencies are shared by eight rays. The registers are
//! the packet's own lanes (`PacketLanes`), eight at a time, loaded as they lie.
//!
//! Each lane is the watertight test of its own ray: its coordinates picked in the ray's own axis
//! order (a per-lane permutation of the triangle's nine floats), then the SSE block test's
//! operations in its order. The rays' constants for the test (axis order, shear) are made for the
//! eight lanes at once from the rays as given, not ray by ray: 1.16x on the kitchen's inside shadow
//! rays, whose packets test one leaf each (601 to 536 instructions a ray;
//! `docs/notes/*-benchmarks-instructions.md`, "Instructions per ray"). A lane with a zero edge
//! function, or with a hit the error bound flags, takes the scalar test, with its ray's constants
//! made for it. The answers are the single-ray
//! leaf's bit for bit, and each ray's events come in its order (triangle by triangle, up to an
//! any-hit answer).
//!
//! The arithmetic is the SSE block test's (`raytrail_core`'s watertight test) written again for
//! 256-bit registers. One form generic over the register width would call the AVX intrinsics from
//! a function not compiled for AVX, and the compiler then leaves them as calls (0.18-0.84x when
//! tried: `docs/notes/*-benchmarks-packet-leaves.md`, "Packet leaves with the rays in the lanes").

use raytrail_core::intersect::{TriangleHit, TriangleTest, REFINE_SCALE, TINY_EDGE};
use raytrail_core::observe::Observer;
use raytrail_core::wide::packet::PacketLanes;
use raytrail_core::wide::WideMemory;
use std::arch::x86_64::{
    __m256, __m256i, _mm256_add_epi32, _mm256_add_ps, _mm256_and_ps, _mm256_andnot_ps, _mm256_blendv_ps,
    _mm256_castps_si256, _mm256_castsi256_ps, _mm256_cmp_ps, _mm256_div_ps, _mm256_loadu_ps, _mm256_loadu_si256,
    _mm256_movemask_ps, _mm256_mul_ps, _mm256_or_ps, _mm256_permutevar8x32_ps, _mm256_set1_epi32, _mm256_set1_ps,
    _mm256_setzero_ps, _mm256_storeu_ps, _mm256_storeu_si256, _mm256_sub_ps, _CMP_GE_OQ, _CMP_GT_OQ, _CMP_LT_OQ,
    _CMP_NEQ_UQ, _CMP_NGT_UQ, _CMP_NLT_UQ,
};

/// Eight rays' watertight constants by lane.
struct RayLanes {
    /// Origins in each ray's axis order.
    origin: [[f32; 8]; 3],
    /// Shear constants.
    shear: [[f32; 8]; 3],
    /// Each ray's axis order.
    axes: [[i32; 8]; 3],
    /// Interval starts.
    tmin: [f32; 8],
    /// Interval ends: each ray's closest hit so far.
    tmax: [f32; 8],
}

/// The answers of one triangle for eight rays: lanes hit, lanes for the scalar test, and the hit
/// lanes' distances and barycentrics.
struct TriangleLanes {
    hit: u32,
    slow: u32,
    t: [f32; 8],
    u: [f32; 8],
    v: [f32; 8],
}

/// Tests leaf `(first, count)` for the rays of `mask` with the rays in lanes, eight lanes of the
/// packet to a register, where `T` is the watertight test; `None` (nothing done) otherwise.
///
/// # Safety
/// The processor must run the AVX2 path ([`crate::x86::available`]).
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
#[inline]
pub(crate) unsafe fn leaf<const W: usize, const N: usize, M, T, O>(
    mem: &M,
    first: u32,
    count: u32,
    mask: u64,
    lanes: &mut PacketLanes<N>,
    obs: &mut [O],
) -> Option<()>
where
    M: WideMemory<W> + ?Sized,
    T: TriangleTest,
    O: Observer,
{
    let mask = mask & lanes.traced;
    if N % 8 != 0 {
        return None;
    }
    if mask != 0 {
        // `T` is the watertight test for every ray or for none: nothing is tested before one
        // ray's constants decide.
        T::sheared(&T::prepare(&lanes.ray(mask.trailing_zeros() as usize)))?;
    }
    for g in 0..N / 8 {
        let mut live = ((mask >> (8 * g)) & 0xff) as u32;
        if live == 0 {
            continue;
        }
        let at = 8 * g;
        let ld = |a: &[f32; N]| _mm256_loadu_ps(a.as_ptr().add(at));
        // Lanes without a ray of `mask` get a direction of (1, 1, 1): finite constants that no
        // test reads.
        let in_mask = crate::x86::lanes::lanes_of(live);
        let dir = |a: usize| _mm256_blendv_ps(_mm256_set1_ps(1.0), ld(&lanes.dir[a]), in_mask);
        let o = &lanes.rays.origin;
        let mut r =
            RayLanes { origin: [[0.0; 8]; 3], shear: [[0.0; 8]; 3], axes: [[0; 8]; 3], tmin: [0.0; 8], tmax: [0.0; 8] };
        shear_lanes([dir(0), dir(1), dir(2)], [ld(&o[0]), ld(&o[1]), ld(&o[2])], &mut r);
        _mm256_storeu_ps(r.tmin.as_mut_ptr(), ld(&lanes.tmin));
        _mm256_storeu_ps(r.tmax.as_mut_ptr(), ld(&lanes.limit));
        for pos in first..first + count {
            if live == 0 {
                break;
            }
            let tri = mem.wide_triangle(pos);
            // SAFETY: AVX2 is this function's own precondition; a triangle's three vertices are
            // nine contiguous floats.
            let h = triangle(&r, tri.as_ptr().cast());
            let prim = mem.prim(pos);
            let mut m = if O::ENABLED { live } else { live & (h.hit | h.slow) };
            while m != 0 {
                let k = m.trailing_zeros() as usize;
                m &= m - 1;
                let (bit, i) = (1 << k, at + k);
                if O::ENABLED {
                    obs[i].primitive(prim);
                }
                let found = if h.slow & bit != 0 {
                    let [a, b, c] = &*tri;
                    let ray = T::prepare(&lanes.ray(i));
                    T::intersect_in_place(&ray, [a.as_ref(), b.as_ref(), c.as_ref()], r.tmin[k], r.tmax[k])
                } else if h.hit & bit != 0 {
                    Some(TriangleHit { t: h.t[k], u: h.u[k], v: h.v[k] })
                } else {
                    None
                };
                let Some(hit) = found else { continue };
                let mut q = lanes.answer(i);
                if q.offer(hit, prim) {
                    lanes.record(i, &q);
                    if O::ENABLED {
                        obs[i].hit(prim, hit.t);
                    }
                    if q.any {
                        live &= !bit;
                    }
                    r.tmax[k] = q.limit();
                }
            }
        }
    }
    Some(())
}

/// The watertight test's per-ray constants (`Watertight::prepare`'s: the dominant axis last, the
/// other two swapped where the direction along it is negative, `dx/dz, dy/dz, 1/dz`) of eight rays
/// at once, each lane the scalar operations in their order: the same selects and the same IEEE
/// divisions, so every lane equals its ray's own constants bit for bit. Lanes without a ray hold a
/// direction of (1, 1, 1) and give finite constants that no test reads.
///
/// # Safety
/// The processor must run the AVX2 path ([`crate::x86::available`]).
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
#[inline]
unsafe fn shear_lanes(d: [__m256; 3], o: [__m256; 3], r: &mut RayLanes) {
    let abs = |x: __m256| _mm256_andnot_ps(_mm256_set1_ps(-0.0), x);
    let (ax, ay, az) = (abs(d[0]), abs(d[1]), abs(d[2]));
    // Ties go to the lower axis, as in the scalar test.
    let x_dom = _mm256_and_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(ax, ay), _mm256_cmp_ps::<_CMP_GE_OQ>(ax, az));
    let y_dom = _mm256_andnot_ps(x_dom, _mm256_cmp_ps::<_CMP_GE_OQ>(ay, az));
    // `select(m, a, b)`: `a` where `m`, as glam's `Vec3A::select`.
    let sel = |m: __m256, a: __m256, b: __m256| _mm256_blendv_ps(b, a, m);
    let rotate = |v: [__m256; 3]| {
        [
            sel(x_dom, v[1], sel(y_dom, v[2], v[0])),
            sel(x_dom, v[2], sel(y_dom, v[0], v[1])),
            sel(x_dom, v[0], sel(y_dom, v[1], v[2])),
        ]
    };
    let (d, o) = (rotate(d), rotate(o));
    let negative = _mm256_cmp_ps::<_CMP_LT_OQ>(d[2], _mm256_setzero_ps());
    let swap = |v: [__m256; 3]| [sel(negative, v[1], v[0]), sel(negative, v[0], v[1]), v[2]];
    let (d, o) = (swap(d), swap(o));
    let axis = |x: i32, y: i32, z: i32| {
        let i = |n: i32| _mm256_castsi256_ps(_mm256_set1_epi32(n));
        _mm256_castps_si256(sel(x_dom, i(x), sel(y_dom, i(y), i(z))))
    };
    let (kx, ky, kz) = (axis(1, 2, 0), axis(2, 0, 1), axis(0, 1, 2));
    let neg = _mm256_castps_si256(negative);
    let pick = |m: __m256i, a: __m256i, b: __m256i| {
        _mm256_castps_si256(sel(_mm256_castsi256_ps(m), _mm256_castsi256_ps(a), _mm256_castsi256_ps(b)))
    };
    let (kx, ky) = (pick(neg, ky, kx), pick(neg, kx, ky));
    let st = |a: &mut [f32; 8], x: __m256| _mm256_storeu_ps(a.as_mut_ptr(), x);
    let sti = |a: &mut [i32; 8], x: __m256i| _mm256_storeu_si256(a.as_mut_ptr().cast::<__m256i>(), x);
    for (a, v) in o.iter().enumerate() {
        st(&mut r.origin[a], *v);
    }
    st(&mut r.shear[0], _mm256_div_ps(d[0], d[2]));
    st(&mut r.shear[1], _mm256_div_ps(d[1], d[2]));
    st(&mut r.shear[2], _mm256_div_ps(_mm256_set1_ps(1.0), d[2]));
    sti(&mut r.axes[0], kx);
    sti(&mut r.axes[1], ky);
    sti(&mut r.axes[2], kz);
}

/// One triangle (its nine floats from `v`) against the rays of `r`.
///
/// # Safety
/// The processor must run the AVX2 path ([`crate::x86::available`]); `v` must point to nine readable floats.
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
#[inline]
unsafe fn triangle(r: &RayLanes, v: *const f32) -> TriangleLanes {
    let splat = |x: f32| _mm256_set1_ps(x);
    let ld = |a: &[f32; 8]| _mm256_loadu_ps(a.as_ptr());
    let ldi = |a: &[i32; 8]| _mm256_loadu_si256(a.as_ptr().cast::<__m256i>());
    // The first eight floats (a, b, and c's x and y), and the eight from the second (c's z last).
    let (head, tail) = (_mm256_loadu_ps(v), _mm256_loadu_ps(v.add(1)));
    let axes = [ldi(&r.axes[0]), ldi(&r.axes[1]), ldi(&r.axes[2])];
    // Vertex `j`'s coordinate on each lane's axis `a`: float `3 j + axis`, c's from `tail`.
    let pick = |j: i32, a: usize| {
        if j < 2 {
            _mm256_permutevar8x32_ps(head, _mm256_add_epi32(axes[a], _mm256_set1_epi32(3 * j)))
        } else {
            _mm256_permutevar8x32_ps(tail, _mm256_add_epi32(axes[a], _mm256_set1_epi32(5)))
        }
    };
    let (ox, oy, oz) = (ld(&r.origin[0]), ld(&r.origin[1]), ld(&r.origin[2]));
    let rel = |j: i32| (_mm256_sub_ps(pick(j, 0), ox), _mm256_sub_ps(pick(j, 1), oy), _mm256_sub_ps(pick(j, 2), oz));
    let ((a0, a1, a2), (b0, b1, b2), (c0, c1, c2)) = (rel(0), rel(1), rel(2));
    let (sxv, syv, szv) = (ld(&r.shear[0]), ld(&r.shear[1]), ld(&r.shear[2]));
    let ax = _mm256_sub_ps(a0, _mm256_mul_ps(sxv, a2));
    let ay = _mm256_sub_ps(a1, _mm256_mul_ps(syv, a2));
    let bx = _mm256_sub_ps(b0, _mm256_mul_ps(sxv, b2));
    let by = _mm256_sub_ps(b1, _mm256_mul_ps(syv, b2));
    let cx = _mm256_sub_ps(c0, _mm256_mul_ps(sxv, c2));
    let cy = _mm256_sub_ps(c1, _mm256_mul_ps(syv, c2));
    let u = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
    let v = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
    let w = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
    let z = _mm256_setzero_ps();
    let abs = |x: __m256| _mm256_andnot_ps(splat(-0.0), x);
    // An edge function below `TINY_EDGE` sends the lane to the scalar test's `f64` fallback.
    let tiny = |x: __m256| _mm256_cmp_ps::<_CMP_LT_OQ>(abs(x), splat(TINY_EDGE));
    let lt = |x: __m256| _mm256_cmp_ps::<_CMP_LT_OQ>(x, z);
    let gt = |x: __m256| _mm256_cmp_ps::<_CMP_GT_OQ>(x, z);
    let zero = _mm256_or_ps(_mm256_or_ps(tiny(u), tiny(v)), tiny(w));
    let neg = _mm256_or_ps(_mm256_or_ps(lt(u), lt(v)), lt(w));
    let pos = _mm256_or_ps(_mm256_or_ps(gt(u), gt(v)), gt(w));
    let det = _mm256_add_ps(_mm256_add_ps(u, v), w);
    let az = _mm256_mul_ps(szv, a2);
    let bz = _mm256_mul_ps(szv, b2);
    let cz = _mm256_mul_ps(szv, c2);
    let t = _mm256_div_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(u, az), _mm256_mul_ps(v, bz)), _mm256_mul_ps(w, cz)),
        det,
    );
    // `!t.is_finite() || t < tmin || t > tmax` rejects: NaN fails `|t| < inf`.
    let finite = _mm256_cmp_ps::<_CMP_LT_OQ>(abs(t), splat(f32::INFINITY));
    let det_ok = _mm256_cmp_ps::<_CMP_NEQ_UQ>(det, z);
    let ahead = _mm256_and_ps(
        _mm256_andnot_ps(_mm256_and_ps(neg, pos), det_ok),
        _mm256_and_ps(finite, _mm256_cmp_ps::<_CMP_NLT_UQ>(t, ld(&r.tmin))),
    );
    let ok = _mm256_and_ps(ahead, _mm256_cmp_ps::<_CMP_NGT_UQ>(t, ld(&r.tmax)));
    let zero = _mm256_movemask_ps(zero) as u32;
    let mut slow = zero;
    let screened = _mm256_movemask_ps(ahead) as u32 & !zero;
    if screened != 0 {
        let m = |p0: __m256, p1: __m256, p2: __m256| {
            _mm256_add_ps(_mm256_add_ps(abs(p0), abs(p1)), _mm256_add_ps(abs(p2), abs(p2)))
        };
        let (ma, mb, mc) = (m(a0, a1, a2), m(b0, b1, b2), m(c0, c1, c2));
        let (sa, sb, sc) =
            (_mm256_add_ps(abs(ax), abs(ay)), _mm256_add_ps(abs(bx), abs(by)), _mm256_add_ps(abs(cx), abs(cy)));
        let e = |mp: __m256, sq: __m256, mq: __m256, sp: __m256| {
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(mp, sq), _mm256_mul_ps(mq, sp)), _mm256_mul_ps(sp, sq))
        };
        let (eu, ev, ew) = (e(mb, sc, mc, sb), e(mc, sa, ma, sc), e(ma, sb, mb, sa));
        let dz = |zz: __m256| abs(_mm256_sub_ps(zz, t));
        let lhs = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(eu, dz(az)), _mm256_mul_ps(ev, dz(bz))),
            _mm256_mul_ps(ew, dz(cz)),
        );
        let rhs = _mm256_mul_ps(splat(REFINE_SCALE), abs(_mm256_mul_ps(t, det)));
        slow |= _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(lhs, rhs)) as u32 & screened;
    }
    let hit = _mm256_movemask_ps(ok) as u32 & !slow;
    let store = |x: __m256| {
        let mut out = [0.0f32; 8];
        _mm256_storeu_ps(out.as_mut_ptr(), x);
        out
    };
    if hit == 0 {
        return TriangleLanes { hit, slow, t: [0.0; 8], u: [0.0; 8], v: [0.0; 8] };
    }
    TriangleLanes { hit, slow, t: store(t), u: store(_mm256_div_ps(v, det)), v: store(_mm256_div_ps(w, det)) }
}

#[cfg(test)]
mod tests {
    use super::{shear_lanes, RayLanes};
    use crate::test_rng::Rng;
    use crate::x86::child_kernel::AvxKernel;
    use glam::Vec3;
    use raytrail_core::geometry::Triangle;
    use raytrail_core::intersect::{TriangleHit, Watertight};
    use raytrail_core::method::Query;
    use raytrail_core::observe::{NoObserver, Observer};
    use raytrail_core::traverse::begin_slab;
    use raytrail_core::wide::packet::{PacketKernel, PacketLanes, ReferencePacketKernel};
    use raytrail_core::wide::{FastKernel, LeafBlock, WideSliceMemory};
    use raytrail_core::Ray;
    use std::arch::x86_64::_mm256_loadu_ps;

    /// Each test and each accepted hit, in order.
    #[derive(Debug, Default, PartialEq)]
    struct Log(Vec<(u32, Option<u32>)>);

    impl Observer for Log {
        fn primitive(&mut self, prim: u32) {
            self.0.push((prim, None));
        }
        fn hit(&mut self, prim: u32, t: f32) {
            self.0.push((prim, Some(t.to_bits())));
        }
    }

    /// Leaves of one to eight triangles sharing vertices on a coarse grid (so edge functions are
    /// often exactly zero), packets of 32 rays aimed at their vertices, edges and insides, some
    /// with a closest hit already: the lanes' answers and each ray's events are the single-ray
    /// leaf's, with and without an observer.
    #[test]
    fn rays_in_lanes_match_the_single_ray_leaf() {
        if crate::x86::lacks_avx2_for("packet leaf") {
            return;
        }
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut hits, mut answered_early) = (0, 0);
        for round in 0..3000 {
            let count = 1 + round % 8;
            let pool: Vec<Vec3> = (0..5).map(|_| Vec3::new(rng.value(), rng.value(), rng.value())).collect();
            let mut pick = || pool[(rng.next() % 5) as usize];
            let triangles: Vec<Triangle> = (0..count).map(|_| Triangle::new(pick(), pick(), pick())).collect();
            let prims: Vec<u32> = (0..count as u32).map(|i| (i * 7 + round as u32) % 11).collect();
            let blocks: Vec<LeafBlock> =
                triangles.chunks(4).zip(prims.chunks(4)).map(|(t, p)| LeafBlock::new(t, p)).collect();
            let mem = WideSliceMemory::<8> { nodes: &[], triangles: &triangles, blocks: &blocks };
            let query = if round % 3 == 0 { Query::Any } else { Query::Closest };
            let mut lanes = PacketLanes::<32>::new(query);
            let mut mask = 0u64;
            for i in 0..32 {
                let tri = triangles[(rng.next() % count as u64) as usize];
                // Barycentric weights in quarters: vertices, edges, insides, and points outside.
                let mut weight = || (rng.next() % 5) as f32 / 4.0;
                let (w0, w1) = (weight(), weight());
                let target = tri.v[0] * w0 + tri.v[1] * w1 + tri.v[2] * (1.0 - w0 - w1);
                let origin = Vec3::new(rng.value(), rng.value(), rng.value()) * 2.0;
                let dir = target - origin;
                let ray = Ray::new(
                    origin,
                    dir,
                    [0.0, 0.5][(rng.next() % 2) as usize],
                    [f32::INFINITY, 1.0][(rng.next() % 2) as usize],
                );
                let Some(slab) = begin_slab(&ray, 8.0) else { continue };
                lanes.set_lane(i, &ray, &slab);
                if query == Query::Closest && rng.next() % 4 == 0 {
                    let mut q = lanes.answer(i);
                    q.offer(TriangleHit { t: (rng.next() % 8) as f32 / 4.0, u: 0.0, v: 0.0 }, (rng.next() % 11) as u32);
                    lanes.record(i, &q);
                }
                if rng.next() % 5 != 0 {
                    mask |= 1 << i;
                }
            }
            let (mut want, mut got, mut quiet) = (lanes, lanes, lanes);
            let (mut want_log, mut got_log): (Vec<Log>, Vec<Log>) =
                ((0..32).map(|_| Log::default()).collect(), (0..32).map(|_| Log::default()).collect());
            let first = 0;
            ReferencePacketKernel::leaf::<8, 32, _, Watertight, FastKernel, _>(
                &mem,
                first,
                count as u32,
                mask,
                &mut want,
                &mut want_log,
            );
            crate::x86::packet::AvxPacketKernel::leaf::<8, 32, _, Watertight, AvxKernel, _>(
                &mem,
                first,
                count as u32,
                mask,
                &mut got,
                &mut got_log,
            );
            let mut no_obs: Vec<NoObserver> = (0..32).map(|_| NoObserver).collect();
            crate::x86::packet::AvxPacketKernel::leaf::<8, 32, _, Watertight, AvxKernel, _>(
                &mem,
                first,
                count as u32,
                mask,
                &mut quiet,
                &mut no_obs,
            );
            for i in 0..32 {
                let answer = |l: &PacketLanes<32>| {
                    let h = l.hit[i];
                    (h.prim, [h.t, h.u, h.v].map(f32::to_bits), l.limit[i].to_bits())
                };
                assert_eq!(answer(&got), answer(&want), "round {round}, lane {i}: {triangles:?}");
                assert_eq!(answer(&quiet), answer(&want), "round {round}, lane {i}, no observer");
                assert_eq!(got_log[i], want_log[i], "round {round}, lane {i}: events");
                let log = &want_log[i].0;
                hits += log.iter().filter(|e| e.1.is_some()).count();
                answered_early +=
                    usize::from(query == Query::Any && log.len() < count && log.last().is_some_and(|e| e.1.is_some()));
            }
        }
        assert!(hits > 10_000, "only {hits} hits");
        assert!(answered_early > 1_000, "only {answered_early} any-hit rays answered before the leaf's end");
    }

    /// `shear_lanes` against `Watertight::prepare`, lane by lane and bit for bit, on directions
    /// with zeros of both signs, exact ties between components (which pick the lower axis) and
    /// every sign: the axis order, the origin in that order and the shear.
    #[test]
    fn lane_constants_are_each_rays_own() {
        if crate::x86::lacks_avx2_for("lane constants") {
            return;
        }
        use raytrail_core::intersect::TriangleTest;
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let (mut checked, mut axes_seen) = (0, [0usize; 3]);
        for _ in 0..20_000 {
            let (mut dir, mut org) = ([[1.0f32; 8]; 3], [[0.0f32; 8]; 3]);
            let mut rays = [None; 8];
            for (k, slot) in rays.iter_mut().enumerate() {
                let d = [rng.value(), rng.value(), rng.value()];
                let o = [rng.value(), rng.value(), rng.value()];
                if d.iter().all(|&x| x == 0.0) {
                    continue;
                }
                for a in 0..3 {
                    (dir[a][k], org[a][k]) = (d[a], o[a]);
                }
                *slot = Some(Ray { origin: o, tmin: 0.0, dir: d, tmax: f32::INFINITY });
            }
            let mut r = RayLanes {
                origin: [[0.0; 8]; 3],
                shear: [[0.0; 8]; 3],
                axes: [[0; 8]; 3],
                tmin: [0.0; 8],
                tmax: [0.0; 8],
            };
            let ld = |v: &[[f32; 8]; 3]| v.map(|a| unsafe { _mm256_loadu_ps(a.as_ptr()) });
            // SAFETY: AVX2 checked above.
            unsafe { shear_lanes(ld(&dir), ld(&org), &mut r) };
            for (k, ray) in rays.iter().enumerate() {
                let Some(ray) = ray else { continue };
                let want = Watertight::prepare(ray);
                let lane = |v: &[[f32; 8]; 3]| [v[0][k], v[1][k], v[2][k]].map(f32::to_bits);
                assert_eq!(lane(&r.origin), want.origin().map(f32::to_bits), "{ray:?}");
                assert_eq!(lane(&r.shear), want.shear().map(f32::to_bits), "{ray:?}");
                assert_eq!([r.axes[0][k], r.axes[1][k], r.axes[2][k]], want.axes().map(|a| a as i32), "{ray:?}");
                axes_seen[want.axes()[2]] += 1;
                checked += 1;
            }
        }
        assert!(checked > 100_000 && axes_seen.iter().all(|&n| n > 10_000), "{checked} {axes_seen:?}");
    }
}
