//! The AVX2 child kernel of every wide walk: an 8-wide node's boxes in one 256-bit operation per
//! plane, three or more hit children ordered by rank; the 4-wide SSE code and the triangle tests
//! compile with AVX2's three-operand encoding inside the walks that use it.

use raytrail_core::intersect::{SlabRay, FAR_PAD};
use raytrail_core::wide::{ChildHits, ChildKernel, FastKernel, StreamRay, WideNode};
use std::arch::x86_64::{
    _mm256_add_ps, _mm256_and_ps, _mm256_and_si256, _mm256_andnot_ps, _mm256_blendv_epi8, _mm256_blendv_ps,
    _mm256_castps_si256, _mm256_castsi256_ps, _mm256_cmp_ps, _mm256_cmpeq_epi32, _mm256_cmpgt_epi32, _mm256_loadu_ps,
    _mm256_loadu_si256, _mm256_max_ps, _mm256_min_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_or_ps, _mm256_or_si256,
    _mm256_set1_epi32, _mm256_set1_ps, _mm256_setr_epi32, _mm256_setzero_si256, _mm256_storeu_ps, _mm256_storeu_si256,
    _mm256_sub_epi32, _mm256_sub_ps, _CMP_EQ_OQ, _CMP_LE_OQ, _CMP_LT_OQ,
};

/// The fast kernel with 8-wide nodes tested in one AVX operation per plane and ordered by
/// [`order_by_rank`] where three or more children are hit. Used only inside this folder's walks
/// (`single_ray`, `stream`, `packet`), each of whose callers has checked for AVX2
/// ([`super::available`]): that is what makes its unchecked AVX calls sound (a check per node cost
/// 2% of a ray's time).
pub(crate) struct AvxKernel;

impl ChildKernel for AvxKernel {
    const BLOCKS: bool = true;

    #[inline(always)]
    fn test<const W: usize>(node: &WideNode<W>, slab: &SlabRay, tmin: f32, tmax: f32) -> ChildHits<W> {
        if W % 8 == 0 {
            // SAFETY: only this folder's walks use this kernel, and only where the AVX2 path runs.
            unsafe { test_avx(node, slab, tmin, tmax) }
        } else {
            FastKernel::test(node, slab, tmin, tmax)
        }
    }

    #[inline(always)]
    fn stream_node<const W: usize>(
        node: &WideNode<W>,
        live: &[u32],
        rays: &[StreamRay],
        masks: &mut [u32],
        t_enter: &mut [[f32; W]],
        keys: &mut [f32; W],
        counts: &mut [u32; W],
    ) {
        if W == 8 {
            // SAFETY: only this folder's walks use this kernel, and only where the AVX2 path runs.
            unsafe { stream_node_avx(node, live, rays, masks, t_enter, keys, counts) }
        } else {
            FastKernel::stream_node(node, live, rays, masks, t_enter, keys, counts)
        }
    }

    #[inline(always)]
    fn order<const W: usize>(hits: &ChildHits<W>, order: &mut [u32; W]) -> usize {
        if W == 8 && hits.mask.count_ones() > 2 {
            // SAFETY: only this folder's walks use this kernel, and only where the AVX2 path runs.
            unsafe { order_by_rank(hits, order) }
        } else {
            FastKernel::order(hits, order)
        }
    }
}

/// Eight children per operation, with [`SlabRay::hit_scalar`]'s operations in its order per lane
/// (`vmaxps(x, acc)` is `keep_max(acc, x)`, likewise `vminps`).
///
/// # Safety
/// The processor must support AVX.
#[target_feature(enable = "avx")]
#[inline]
unsafe fn test_avx<const W: usize>(node: &WideNode<W>, s: &SlabRay, tmin: f32, tmax: f32) -> ChildHits<W> {
    let mut out = ChildHits { t_enter: [f32::INFINITY; W], mask: 0 };
    let (o, inv) = (s.origin.to_array(), s.inv_dir.to_array());
    // The node's six plane arrays in `WideNode`'s order (`lo` x, y, z, then `hi` x, y, z), `W`
    // floats each, read through one pointer to the whole node.
    let planes = (node as *const WideNode<W>).cast::<f32>();
    let mut lane = 0;
    while lane + 8 <= W {
        let splat = |x: f32| _mm256_set1_ps(x);
        let (mut t_enter, mut t_exit) = (splat(tmin), splat(tmax));
        for a in 0..3 {
            // Planes picked by the direction's sign (`negative`, as the reference picks them) as
            // an address rather than by a blend of both: the loads start the chain. 1.02 on the
            // kitchen's inside camera and diffuse rays (`docs/notes/*-benchmarks-leaf-blocks.md`,
            // "Packets' box tests by ray"). The address is computed from the sign, not branched
            // on: a branch on the x sign missed 2.5 times a ray on shuffled diffuse rays, whose
            // signs change from ray to ray (`docs/notes/*-single-ray-selects.md`).
            let neg = usize::from(s.negative[a]);
            let (near_plane, far_plane) = (a + 3 * neg, a + 3 - 3 * neg);
            // SAFETY: plane arrays 0..6 of `W` floats lie inside the node (`repr(C)`, no
            // padding), eight floats from `lane <= W - 8` inside each.
            let (near, far) = unsafe {
                (_mm256_loadu_ps(planes.add(near_plane * W + lane)), _mm256_loadu_ps(planes.add(far_plane * W + lane)))
            };
            let (oa, ia) = (splat(o[a]), splat(inv[a]));
            let tn = _mm256_mul_ps(_mm256_sub_ps(near, oa), ia);
            let tf = _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(far, oa), ia), splat(FAR_PAD));
            t_enter = _mm256_max_ps(tn, t_enter);
            t_exit = _mm256_min_ps(tf, t_exit);
        }
        let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(t_enter, _mm256_add_ps(t_exit, splat(s.slack)));
        let kept = _mm256_or_ps(_mm256_and_ps(hit, t_enter), _mm256_andnot_ps(hit, splat(f32::INFINITY)));
        // SAFETY: as the loads.
        unsafe { _mm256_storeu_ps(out.t_enter.as_mut_ptr().add(lane), kept) };
        out.mask |= (_mm256_movemask_ps(hit) as u32) << lane;
        lane += 8;
    }
    out
}

/// [`ChildKernel::stream_node`] for eight children: the node's planes loaded once, each ray's
/// test the single-ray test's operations in its order (near and far planes picked by the sign bit
/// of `1 / d`, which is `d`'s, as the packet kernel picks them: no branch on a sign that changes
/// from ray to ray), the keys folded by `vminps(t, key)` (a tie keeps the key) and the counts by a
/// subtraction, both in registers over the list.
///
/// # Safety
/// The processor must run the AVX2 path ([`available`]); `W` must be 8; `masks` and `t_enter`
/// must hold an entry per ray of `live`, and every ray of `live` must index `rays`.
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
#[inline]
#[allow(clippy::too_many_arguments)]
unsafe fn stream_node_avx<const W: usize>(
    node: &WideNode<W>,
    live: &[u32],
    rays: &[StreamRay],
    masks: &mut [u32],
    t_enter: &mut [[f32; W]],
    keys: &mut [f32; W],
    counts: &mut [u32; W],
) {
    let ld = |a: &[f32; W]| _mm256_loadu_ps(a.as_ptr());
    let planes =
        [(ld(&node.lo[0]), ld(&node.hi[0])), (ld(&node.lo[1]), ld(&node.hi[1])), (ld(&node.lo[2]), ld(&node.hi[2]))];
    let splat = _mm256_set1_ps;
    let (mut key, mut count) = (ld(keys), _mm256_loadu_si256(counts.as_ptr().cast()));
    for (k, &r) in live.iter().enumerate() {
        let ray = rays.get_unchecked(r as usize);
        let (s, (lo, hi)) = (&ray.slab, ray.interval);
        let (o, inv) = (s.origin.to_array(), s.inv_dir.to_array());
        let (mut te, mut tx) = (splat(lo), splat(hi));
        for (a, &(l, h)) in planes.iter().enumerate() {
            let (oa, ia) = (splat(o[a]), splat(inv[a]));
            let (near, far) = (_mm256_blendv_ps(l, h, ia), _mm256_blendv_ps(h, l, ia));
            let tn = _mm256_mul_ps(_mm256_sub_ps(near, oa), ia);
            let tf = _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(far, oa), ia), splat(FAR_PAD));
            te = _mm256_max_ps(tn, te);
            tx = _mm256_min_ps(tf, tx);
        }
        let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(te, _mm256_add_ps(tx, splat(s.slack)));
        let kept = _mm256_blendv_ps(splat(f32::INFINITY), te, hit);
        _mm256_storeu_ps(t_enter.get_unchecked_mut(k).as_mut_ptr(), kept);
        key = _mm256_min_ps(kept, key);
        count = _mm256_sub_epi32(count, _mm256_castps_si256(hit));
        *masks.get_unchecked_mut(k) = _mm256_movemask_ps(hit) as u32;
    }
    _mm256_storeu_ps(keys.as_mut_ptr(), key);
    _mm256_storeu_si256(counts.as_mut_ptr().cast(), count);
}

/// Three or more hit children of an 8-wide node ordered without a branch: each child's rank is
/// the number of children before it in the order of
/// [`sort_keys`](raytrail_core::wide::sort_keys) (entry distance, then slot; a missed child ranks
/// after every hit one), counted by eight vector comparisons, and the child is written at its
/// rank. The order is the sorting network's and the reference's insertion sort's, since all three
/// sort by the same total order; the network compiled to two branches per compare-and-swap here.
///
/// # Safety
/// The processor must run the AVX2 path ([`crate::x86::available`]).
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
#[inline]
unsafe fn order_by_rank<const W: usize>(hits: &ChildHits<W>, order: &mut [u32; W]) -> usize {
    if W != 8 {
        // The loads below read eight lanes.
        return FastKernel::order(hits, order);
    }
    // The sort keys every kernel orders by, `sort_keys`'s made by blends on the hit lanes: its
    // selects compiled to a branch per child, which missed 0.8 times a ray on shuffled diffuse
    // rays. Slots count as integers below 16, so the signed comparison of their bits is theirs.
    let bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    let hit = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(hits.mask as i32), bit), bit);
    let keys = _mm256_blendv_ps(
        _mm256_set1_ps(f32::INFINITY),
        _mm256_loadu_ps(hits.t_enter.as_ptr()),
        _mm256_castsi256_ps(hit),
    );
    let slots = _mm256_blendv_epi8(
        _mm256_setr_epi32(8, 9, 10, 11, 12, 13, 14, 15),
        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
        hit,
    );
    let (mut k, mut s) = ([0f32; 8], [0u32; 8]);
    _mm256_storeu_ps(k.as_mut_ptr(), keys);
    _mm256_storeu_si256(s.as_mut_ptr().cast(), slots);
    let mut rank = _mm256_setzero_si256();
    for j in 0..8 {
        let (kj, sj) = (_mm256_set1_ps(k[j]), _mm256_set1_epi32(s[j] as i32));
        let less = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LT_OQ>(kj, keys));
        let tie =
            _mm256_and_si256(_mm256_castps_si256(_mm256_cmp_ps::<_CMP_EQ_OQ>(kj, keys)), _mm256_cmpgt_epi32(slots, sj));
        // A comparison that holds is all ones, -1: subtracting it counts it.
        rank = _mm256_sub_epi32(rank, _mm256_or_si256(less, tie));
    }
    let mut r = [0u32; 8];
    _mm256_storeu_si256(r.as_mut_ptr().cast(), rank);
    for (slot, &at) in r.iter().enumerate() {
        // Ranks are a permutation of 0..8 (the order is total over distinct slots).
        order[at as usize % W] = slot as u32;
    }
    hits.mask.count_ones() as usize
}
#[cfg(test)]
mod tests {
    use super::super::lacks_avx2_for;
    use super::*;
    use glam::Vec3;
    use raytrail_core::wide::{ReferenceKernel, WideChild};
    use raytrail_core::Ray;

    /// Ordinary values with zeros of both signs, infinities, NaN, a subnormal and exact repeats.
    struct Values(u64);

    impl Values {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            match self.0 % 16 {
                0 => 0.0,
                1 => -0.0,
                2 => [0.5, -0.25, 1.0, 3.0][(self.0 >> 8) as usize % 4],
                3 => [f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 1e-40][(self.0 >> 8) as usize % 4],
                _ => ((self.0 >> 8) % 2001) as f32 / 256.0 - 1000.0 / 256.0,
            }
        }
    }

    #[test]
    fn avx_kernel_matches_the_reference_bit_for_bit_on_adversarial_values() {
        if lacks_avx2_for("kernel") {
            return;
        }
        let mut v = Values(0x9e37_79b9_7f4a_7c15);
        let mut hits = 0;
        for _ in 0..100_000 {
            let ray = Ray {
                origin: [v.next(), v.next(), v.next()],
                tmin: v.next(),
                dir: [v.next(), v.next(), v.next()],
                tmax: v.next(),
            };
            let slab = SlabRay { slack: [0.0, 1e-5, f32::INFINITY][(v.0 % 3) as usize], ..SlabRay::new(&ray) };
            let mut node = WideNode::<8>::EMPTY;
            for i in 0..8 {
                if v.next() < 0.0 {
                    continue;
                }
                let (lo, hi) = (Vec3::new(v.next(), v.next(), v.next()), Vec3::new(v.next(), v.next(), v.next()));
                node.set_child(i, lo, hi, WideChild::Node(i as u32));
            }
            let (a, r) = (
                AvxKernel::test(&node, &slab, ray.tmin, ray.tmax),
                ReferenceKernel::test(&node, &slab, ray.tmin, ray.tmax),
            );
            assert_eq!(
                (a.mask, a.t_enter.map(f32::to_bits)),
                (r.mask, r.t_enter.map(f32::to_bits)),
                "{ray:?} {node:?}"
            );
            hits += r.mask.count_ones();
            let (mut oa, mut or) = ([0; 8], [0; 8]);
            let (na, nr) = (AvxKernel::order(&a, &mut oa), ReferenceKernel::order(&r, &mut or));
            assert_eq!((na, &oa[..na]), (nr, &or[..nr]), "{:?}", r.t_enter);
        }
        assert!(hits > 20_000, "only {hits} child hits");
    }

    /// The rank order on ties: equal keys (zeros of both signs among them) keep slot order, and
    /// every count of hit children from three to eight.
    #[test]
    fn rank_order_matches_the_reference_on_ties() {
        if lacks_avx2_for("order") {
            return;
        }
        let keys = [0.0, -0.0, 1.0, 1.0, 0.5, 0.0, 1.0, -0.0];
        for mask in 0u32..256 {
            let t_enter = core::array::from_fn(|i| if mask & (1 << i) != 0 { keys[i] } else { f32::INFINITY });
            let hits = ChildHits::<8> { t_enter, mask };
            let (mut oa, mut or) = ([0; 8], [0; 8]);
            let (na, nr) = (AvxKernel::order(&hits, &mut oa), ReferenceKernel::order(&hits, &mut or));
            assert_eq!((na, &oa[..na]), (nr, &or[..nr]), "mask {mask:#b}");
        }
    }
}
