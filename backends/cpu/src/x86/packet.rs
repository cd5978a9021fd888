//! The AVX2 box tests of a wide packet ([`raytrail_core::wide::packet`]): eight rays to a
//! register, one child at a time, each lane the single-ray AVX test's operations in its order.
//! Before that, the node's children are culled for the whole packet at once by an interval test
//! over the packet's ranges of origins and reciprocal directions: rounding is monotonic, so the
//! interval's ends bound every ray's computed distances and the cull never drops a child that a
//! ray's own test would keep. It only removes work: the answers are [`ReferencePacketKernel`]'s.
//! Where the packet is sparse (few rays per register, and no cull for mixed directions, as for
//! diffuse and ambient-occlusion rays), the tests run the other way round: each ray tests all eight
//! children at once, as the single-ray test does, and its hits are merged into the children's masks
//! and keys.
//!
//! [`ReferencePacketKernel`]: raytrail_core::wide::packet::ReferencePacketKernel

use super::child_kernel::AvxKernel;
use super::lanes::{horizontal, lanes_of, Fold};
use raytrail_core::intersect::{TriangleTest, FAR_PAD};
use raytrail_core::method::Query;
use raytrail_core::observe::Observer;
use raytrail_core::wide::packet::{
    trace_wide_packets, PacketHits, PacketKernel, PacketLanes, PacketRays, ReferencePacketKernel,
};
use raytrail_core::wide::traverse::WideRoot;
use raytrail_core::wide::{ChildKernel, WideMemory, WideNode, EMPTY_CHILD};
use raytrail_core::{Hit, Ray};
use std::arch::x86_64::{
    __m256, _mm256_add_ps, _mm256_and_ps, _mm256_and_si256, _mm256_blendv_ps, _mm256_castps_si256,
    _mm256_castsi256_si128, _mm256_cmp_ps, _mm256_cvtepi32_epi64, _mm256_extracti128_si256, _mm256_loadu_ps,
    _mm256_max_ps, _mm256_min_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_or_si256, _mm256_set1_epi64x,
    _mm256_set1_ps, _mm256_setzero_si256, _mm256_storeu_ps, _mm256_storeu_si256, _mm256_sub_ps, _CMP_GT_OQ, _CMP_LE_OQ,
};

/// The packet kernel of [`trace_batch`], used only there (and by the tests, after their own AVX2
/// check): `trace_batch`'s caller has checked for AVX2, which makes its unchecked AVX calls
/// sound.
pub(crate) struct AvxPacketKernel;

impl PacketKernel for AvxPacketKernel {
    #[inline(always)]
    fn test<const W: usize, const N: usize>(node: &WideNode<W>, rays: &PacketRays<N>, mask: u64) -> PacketHits<W> {
        if W == 8 && N % 8 == 0 {
            // SAFETY: only `trace_batch` uses this kernel, and only where the AVX2 path runs.
            unsafe { test_avx(node, rays, mask) }
        } else {
            ReferencePacketKernel::test(node, rays, mask)
        }
    }

    /// Eight lanes per operation ([`crate::x86::packet_begin`]).
    #[inline(always)]
    fn begin<const N: usize>(rays: &[Ray], scene_scale: f32, lanes: &mut PacketLanes<N>) {
        if N % 8 == 0 {
            // SAFETY: as `test`.
            unsafe { crate::x86::packet_begin::begin(rays, scene_scale, lanes) }
        } else {
            ReferencePacketKernel::begin(rays, scene_scale, lanes)
        }
    }

    /// With the rays in the lanes ([`crate::x86::packet_leaf`]) where the test is the watertight
    /// one; otherwise each ray alone.
    #[inline(always)]
    fn leaf<const W: usize, const N: usize, M, T, K, O>(
        mem: &M,
        first: u32,
        count: u32,
        mask: u64,
        lanes: &mut PacketLanes<N>,
        obs: &mut [O],
    ) where
        M: WideMemory<W> + ?Sized,
        T: TriangleTest,
        K: ChildKernel,
        O: Observer,
    {
        // SAFETY: as `test`.
        if unsafe { crate::x86::packet_leaf::leaf::<W, N, M, T, O>(mem, first, count, mask, lanes, obs) }.is_none() {
            ReferencePacketKernel::leaf::<W, N, M, T, K, O>(mem, first, count, mask, lanes, obs);
        }
    }

    #[inline(always)]
    fn reaching<const N: usize>(key: f32, rays: &PacketRays<N>, mask: u64) -> u64 {
        if N % 8 == 0 {
            // SAFETY: as `test`.
            unsafe { reaching_avx(key, rays, mask) }
        } else {
            ReferencePacketKernel::reaching(key, rays, mask)
        }
    }
}

/// # Safety
/// The processor must run the AVX2 path ([`crate::x86::available`]); `N` must be a multiple of 8.
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
#[inline]
unsafe fn reaching_avx<const N: usize>(key: f32, p: &PacketRays<N>, mask: u64) -> u64 {
    let k = _mm256_set1_ps(key);
    let mut out = 0u64;
    for g in 0..N / 8 {
        let t_hi = _mm256_loadu_ps(p.t_hi.as_ptr().add(8 * g));
        out |= (_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(k, t_hi)) as u64) << (8 * g);
    }
    out & mask
}

/// # Safety
/// The processor must run the AVX2 path ([`crate::x86::available`]); `W` must be 8 and `N` a multiple of 8.
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
#[inline]
unsafe fn test_avx<const W: usize, const N: usize>(node: &WideNode<W>, p: &PacketRays<N>, mask: u64) -> PacketHits<W> {
    let mut todo = cull(node, p);
    // By child, a register of eight rays per test, costs a test per child and register with a ray
    // of `mask`; by ray, all eight children per test, a test per ray. Scattered packets (mixed
    // signs: no cull; few rays per register) are cheaper by ray.
    let registers = (0..N / 8).filter(|g| (mask >> (8 * g)) & 0xff != 0).count() as u32;
    if mask.count_ones() < todo.count_ones() * registers {
        return test_by_ray(node, p, mask);
    }
    let mut out = PacketHits { key: [f32::INFINITY; W], rays: [0; W] };
    let ld = |a: &[f32; N], at: usize| _mm256_loadu_ps(a.as_ptr().add(at));
    while todo != 0 {
        let c = todo.trailing_zeros() as usize;
        todo &= todo - 1;
        let mut key = _mm256_set1_ps(f32::INFINITY);
        let mut rays = 0u64;
        for g in 0..N / 8 {
            let group = ((mask >> (8 * g)) & 0xff) as i32;
            if group == 0 {
                continue;
            }
            let at = 8 * g;
            let (mut t_enter, mut t_exit) = (ld(&p.t_lo, at), ld(&p.t_hi, at));
            for a in 0..3 {
                let (lo, hi) = (_mm256_set1_ps(node.lo[a][c % W]), _mm256_set1_ps(node.hi[a][c % W]));
                (t_enter, t_exit) = slab_axis(lo, hi, ld(&p.origin[a], at), ld(&p.inv_dir[a], at), t_enter, t_exit);
            }
            let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(t_enter, _mm256_add_ps(t_exit, ld(&p.slack, at)));
            let hit = _mm256_and_ps(hit, lanes_of(group as u32));
            rays |= (_mm256_movemask_ps(hit) as u64) << at;
            key = _mm256_min_ps(_mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), t_enter, hit), key);
        }
        if rays != 0 {
            out.rays[c % W] = rays;
            out.key[c % W] = horizontal(key, Fold::Min);
        }
    }
    out
}

/// [`test_avx`] one ray at a time, all eight children per operation: each ray's test is the
/// single-ray AVX test's (`crate::x86::child_kernel`), the child's key the least entry distance over the rays in
/// lane order (`vminps(new, key)` keeps `key` on a tie, as the reference keeps the first).
///
/// # Safety
/// As [`test_avx`].
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
#[inline]
unsafe fn test_by_ray<const W: usize, const N: usize>(
    node: &WideNode<W>,
    p: &PacketRays<N>,
    mask: u64,
) -> PacketHits<W> {
    let s = _mm256_set1_ps;
    let planes = |a: usize| (_mm256_loadu_ps(node.lo[a].as_ptr()), _mm256_loadu_ps(node.hi[a].as_ptr()));
    let (x, y, z) = (planes(0), planes(1), planes(2));
    let mut key = s(f32::INFINITY);
    // Per slot, the rays that hit it as 64-bit lanes: slots 0-3, then 4-7.
    let (mut low, mut high) = (_mm256_setzero_si256(), _mm256_setzero_si256());
    let mut m = mask;
    while m != 0 {
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        let (mut t_enter, mut t_exit) = (s(p.t_lo[i]), s(p.t_hi[i]));
        for (a, (lo, hi)) in [x, y, z].into_iter().enumerate() {
            (t_enter, t_exit) = slab_axis(lo, hi, s(p.origin[a][i]), s(p.inv_dir[a][i]), t_enter, t_exit);
        }
        let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(t_enter, _mm256_add_ps(t_exit, s(p.slack[i])));
        key = _mm256_min_ps(_mm256_blendv_ps(s(f32::INFINITY), t_enter, hit), key);
        let hit = _mm256_castps_si256(hit);
        let bit = _mm256_set1_epi64x(1i64 << i);
        low = _mm256_or_si256(low, _mm256_and_si256(_mm256_cvtepi32_epi64(_mm256_castsi256_si128(hit)), bit));
        high = _mm256_or_si256(high, _mm256_and_si256(_mm256_cvtepi32_epi64(_mm256_extracti128_si256::<1>(hit)), bit));
    }
    let mut out = PacketHits { key: [f32::INFINITY; W], rays: [0; W] };
    _mm256_storeu_ps(out.key.as_mut_ptr(), key);
    _mm256_storeu_si256(out.rays.as_mut_ptr().cast(), low);
    _mm256_storeu_si256(out.rays.as_mut_ptr().add(4).cast(), high);
    out
}

/// One axis of the slab test in eight lanes, each the single-ray test's operations in its order:
/// near and far planes picked by the sign bit of `inv` (`1 / d`, whose sign is `d`'s), their
/// distances (the far one padded) folded into the entry and exit distances. Both forms of
/// [`test_avx`] test an axis with it.
///
/// # Safety
/// The processor must support AVX.
#[target_feature(enable = "avx")]
#[inline]
unsafe fn slab_axis(
    lo: __m256,
    hi: __m256,
    o: __m256,
    inv: __m256,
    t_enter: __m256,
    t_exit: __m256,
) -> (__m256, __m256) {
    let (near, far) = (_mm256_blendv_ps(lo, hi, inv), _mm256_blendv_ps(hi, lo, inv));
    let tn = _mm256_mul_ps(_mm256_sub_ps(near, o), inv);
    let tf = _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(far, o), inv), _mm256_set1_ps(FAR_PAD));
    (_mm256_max_ps(tn, t_enter), _mm256_min_ps(tf, t_exit))
}

/// The children some ray of the packet may hit (a bit per slot): the others are culled by the
/// interval test, all eight at once. Packets whose reciprocal directions differ in sign on an axis
/// or are not finite keep every non-empty child.
///
/// # Safety
/// As [`test_avx`].
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
#[inline]
unsafe fn cull<const W: usize, const N: usize>(node: &WideNode<W>, p: &PacketRays<N>) -> u32 {
    let present = (0..W).fold(0u32, |m, s| m | u32::from(node.child[s] != EMPTY_CHILD) << s);
    let one_sign = p.inv_range.iter().all(|&(l, h)| (l > 0.0 && h.is_finite()) || (h < 0.0 && l.is_finite()));
    if !one_sign {
        return present;
    }
    let s = _mm256_set1_ps;
    let (mut t_enter, mut t_exit) = (s(p.t_lo_min), s(p.t_hi_max));
    for a in 0..3 {
        let (lo, hi) = (_mm256_loadu_ps(node.lo[a].as_ptr()), _mm256_loadu_ps(node.hi[a].as_ptr()));
        let (near, far) = if p.inv_range[a].0 < 0.0 { (hi, lo) } else { (lo, hi) };
        let ((o0, o1), (i0, i1)) = (p.origin_range[a], p.inv_range[a]);
        let (o0, o1, i0, i1) = (s(o0), s(o1), s(i0), s(i1));
        // Each ray's rounded `(plane - o) * inv` lies between the least and the greatest of the
        // four corner products (the product is monotonic in each factor, and so is rounding).
        let corners = |x0: __m256, x1: __m256| {
            [_mm256_mul_ps(x0, i0), _mm256_mul_ps(x0, i1), _mm256_mul_ps(x1, i0), _mm256_mul_ps(x1, i1)]
        };
        let n = corners(_mm256_sub_ps(near, o1), _mm256_sub_ps(near, o0));
        let f = corners(_mm256_sub_ps(far, o1), _mm256_sub_ps(far, o0));
        let tn = _mm256_min_ps(_mm256_min_ps(n[0], n[1]), _mm256_min_ps(n[2], n[3]));
        let tf = _mm256_max_ps(_mm256_max_ps(f[0], f[1]), _mm256_max_ps(f[2], f[3]));
        t_enter = _mm256_max_ps(t_enter, tn);
        // The padding multiply raises a positive exit and lowers a negative one: keep the larger.
        t_exit = _mm256_min_ps(t_exit, _mm256_max_ps(_mm256_mul_ps(tf, s(FAR_PAD)), tf));
    }
    let missed = _mm256_cmp_ps::<_CMP_GT_OQ>(t_enter, _mm256_add_ps(t_exit, s(p.slack_max)));
    present & !(_mm256_movemask_ps(missed) as u32)
}

/// [`trace_wide_packets`] with the AVX2 child kernel and packet kernel, compiled for AVX2.
///
/// # Safety
/// The processor must run the AVX2 path ([`crate::x86::available`]).
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
pub(crate) unsafe fn trace_batch<const W: usize, M: WideMemory<W> + ?Sized, T: TriangleTest, O: Observer + Default>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    done: impl FnMut(usize, O),
) {
    trace_wide_packets::<W, M, T, AvxKernel, AvxPacketKernel, O>(mem, root, rays, hits, query, done);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;
    use glam::Vec3;
    use raytrail_core::traverse::begin_slab;
    use raytrail_core::wide::WideChild;

    /// Packets of 32 rays, half of them of one octant (where the interval cull applies), against
    /// nodes of random boxes with empty slots: every mask and key the reference's, and the rays
    /// reaching a key alike.
    #[test]
    fn avx_packet_kernel_matches_the_reference() {
        if crate::x86::lacks_avx2_for("packet kernel") {
            return;
        }
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let (mut culled_packets, mut hits) = (0, 0);
        for round in 0..4000 {
            let one_octant = round % 2 == 0;
            let signs = [rng.next() % 2 == 0, rng.next() % 2 == 0, rng.next() % 2 == 0];
            let mut p = PacketRays::<32>::EMPTY;
            let mut mask = 0u64;
            for i in 0..32 {
                let mut dir = [rng.value(), rng.value(), rng.value()];
                if one_octant {
                    for a in 0..3 {
                        dir[a] = if signs[a] { -(dir[a].abs() + 0.25) } else { dir[a].abs() + 0.25 };
                    }
                }
                let spread = if one_octant { 0.05 } else { 1.0 };
                let ray = Ray {
                    origin: [rng.value() * spread, rng.value() * spread, rng.value() * spread],
                    tmin: [0.0, 0.5][(rng.next() % 2) as usize],
                    dir,
                    tmax: [f32::INFINITY, 3.0][(rng.next() % 2) as usize],
                };
                let Some(slab) = begin_slab(&ray, 8.0) else { continue };
                p.set_lane(i, &slab, ray.tmin, ray.tmax);
                if rng.next() % 4 != 0 {
                    mask |= 1 << i;
                }
            }
            let mut node = WideNode::<8>::EMPTY;
            for s in 0..8 {
                if rng.next() % 5 == 0 {
                    continue;
                }
                let (a, b) = (
                    Vec3::new(rng.value(), rng.value(), rng.value()),
                    Vec3::new(rng.value(), rng.value(), rng.value()),
                );
                node.set_child(s, a.min(b), a.max(b), WideChild::Node(s as u32));
            }
            // SAFETY: AVX2 checked above.
            let got = unsafe { test_avx(&node, &p, mask) };
            let want = ReferencePacketKernel::test(&node, &p, mask);
            assert_eq!(got.rays, want.rays, "round {round}");
            assert_eq!(got.key, want.key, "round {round}");
            // Both orders of the tests, whichever `test_avx` picked.
            // SAFETY: AVX2 checked above.
            let by_ray = unsafe { test_by_ray(&node, &p, mask) };
            assert_eq!(
                (by_ray.rays, by_ray.key.map(f32::to_bits)),
                (want.rays, want.key.map(f32::to_bits)),
                "round {round}"
            );
            hits += want.rays.iter().filter(|&&r| r != 0).count();
            // SAFETY: as above.
            if unsafe { cull(&node, &p) } != (0..8).fold(0, |m, s| m | u32::from(node.child[s] != EMPTY_CHILD) << s) {
                culled_packets += 1;
            }
            for key in [f32::NEG_INFINITY, -1.0, 0.0, 0.5, 2.0, 3.0, f32::INFINITY] {
                assert_eq!(
                    AvxPacketKernel::reaching(key, &p, mask),
                    ReferencePacketKernel::reaching(key, &p, mask),
                    "round {round}, key {key}"
                );
            }
        }
        assert!(hits > 2_000 && culled_packets > 200, "{hits} child hits, {culled_packets} packets culled");
    }
}
