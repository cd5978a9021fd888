//! How a traversal tests a node's children and orders the hit ones: the plain reference, and the
//! fast path (all children's boxes at once, a sorting network) that must equal it bit for bit.

use super::network::{sort_insertion, sort_network};
use super::node::WideNode;
use crate::intersect::SlabRay;

/// The entry distance of each child slot and a mask of the slots whose box the ray hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChildHits<const W: usize> {
    /// Entry distances (meaningful where `mask` is set).
    pub t_enter: [f32; W],
    /// Bit `i` set where child slot `i` is hit.
    pub mask: u32,
}

/// Tests a node's child boxes and orders the hit children, and says how leaves are tested.
pub trait ChildKernel {
    /// Whether leaves are tested four triangles at once ([`TriangleTest::intersect_block`]) or
    /// one at a time; the answers are the same.
    ///
    /// [`TriangleTest::intersect_block`]: crate::intersect::TriangleTest::intersect_block
    const BLOCKS: bool;
    /// Whether any-hit queries also visit hit children nearest first. Guthe (Sec. 4.2) pushes
    /// them unsorted, the default; the sorted form is there to measure that choice against.
    const SORTED_ANY: bool = false;
    /// The slab test ([`SlabRay::hit`]) of every child box over `[tmin, tmax]`.
    fn test<const W: usize>(node: &WideNode<W>, slab: &SlabRay, tmin: f32, tmax: f32) -> ChildHits<W>;
    /// Writes the hit slots to `order` nearest first (ties to the smaller slot) and returns how
    /// many there are.
    fn order<const W: usize>(hits: &ChildHits<W>, order: &mut [u32; W]) -> usize;

    /// [`ChildKernel::test`] for the rays of a stream ([`crate::wide::ray_stream`]) at one
    /// node: for the `k`-th ray `r` of `live`, its slab constants `rays[r].slab` tested over
    /// `rays[r].interval`, its hit mask written to `masks[k]` and its entry distances to `t_enter[k]`
    /// (`+inf` for a child it misses); per child, the least entry distance over the rays in list
    /// order (a tie keeps the first) in `keys` and the rays that hit it counted in `counts`. A
    /// vector kernel keeps the node's planes and the keys in registers over the whole list.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn stream_node<const W: usize>(
        node: &WideNode<W>,
        live: &[u32],
        rays: &[StreamRay],
        masks: &mut [u32],
        t_enter: &mut [[f32; W]],
        keys: &mut [f32; W],
        counts: &mut [u32; W],
    ) {
        for ((&r, mask), t_out) in live.iter().zip(masks.iter_mut()).zip(t_enter.iter_mut()) {
            let ray = &rays[r as usize];
            let (lo, hi) = ray.interval;
            let h = Self::test::<W>(node, &ray.slab, lo, hi);
            for c in 0..W {
                let hit = (h.mask >> c) & 1 != 0;
                let t = if hit { h.t_enter[c] } else { f32::INFINITY };
                t_out[c] = t;
                keys[c] = if t < keys[c] { t } else { keys[c] };
                counts[c] += u32::from(hit);
            }
            *mask = h.mask;
        }
    }
}

/// What a stream's box tests read of one ray ([`ChildKernel::stream_node`]), with its interval
/// start for its leaves: one cache line, where the slab constants and the interval in two arrays
/// took two.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct StreamRay {
    /// Slab-test constants.
    pub slab: SlabRay,
    /// The box interval: `RayContext::box_interval` of the closest hit so far.
    pub interval: (f32, f32),
    /// The ray's own interval start (its leaves' triangle tests).
    pub tmin: f32,
}

/// The reference: one child at a time through [`SlabRay::hit_scalar`], an insertion sort. The
/// serial reference backend traverses with it, and every fast path is checked against it.
#[derive(Clone, Copy, Debug, Default)]
pub struct ReferenceKernel;

impl ChildKernel for ReferenceKernel {
    const BLOCKS: bool = false;

    #[inline(always)]
    fn test<const W: usize>(node: &WideNode<W>, slab: &SlabRay, tmin: f32, tmax: f32) -> ChildHits<W> {
        let mut out = ChildHits { t_enter: [f32::INFINITY; W], mask: 0 };
        for i in 0..W {
            let (lo, hi) = node.child_box(i);
            if let Some(h) = slab.hit_scalar(lo, hi, tmin, tmax) {
                out.t_enter[i] = h.t_enter;
                out.mask |= 1 << i;
            }
        }
        out
    }

    #[inline(always)]
    fn order<const W: usize>(hits: &ChildHits<W>, order: &mut [u32; W]) -> usize {
        let (mut keys, mut slots) = sort_keys(hits);
        sort_insertion(&mut keys, &mut slots);
        *order = slots;
        hits.mask.count_ones() as usize
    }
}

/// The fast path: every child box at once (SSE on x86_64, four lanes per instruction), hit
/// children ordered by the sorting network. Bit-identical to [`ReferenceKernel`].
#[derive(Clone, Copy, Debug, Default)]
pub struct FastKernel;

impl ChildKernel for FastKernel {
    const BLOCKS: bool = true;

    #[inline(always)]
    fn test<const W: usize>(node: &WideNode<W>, slab: &SlabRay, tmin: f32, tmax: f32) -> ChildHits<W> {
        #[cfg(target_arch = "x86_64")]
        if W % 4 == 0 {
            return sse::test(node, slab, tmin, tmax);
        }
        ReferenceKernel::test(node, slab, tmin, tmax)
    }

    /// The network over as few lanes as the hit children need: one hit needs none, two one
    /// exchange, up to four the 4-lane network on the hits gathered into four lanes. The order is
    /// total, so each gives what the full network gives.
    #[inline(always)]
    fn order<const W: usize>(hits: &ChildHits<W>, order: &mut [u32; W]) -> usize {
        let n = hits.mask.count_ones() as usize;
        let first = hits.mask.trailing_zeros();
        match n {
            0 | 1 => order[0] = first,
            2 => {
                let second = (hits.mask & (hits.mask - 1)).trailing_zeros();
                let (a, b) = (hits.t_enter[first as usize], hits.t_enter[second as usize]);
                // `first < second`, so a tie keeps them in slot order.
                (order[0], order[1]) = if b < a { (second, first) } else { (first, second) };
            }
            3 | 4 if W > 4 => {
                let (mut keys, mut slots) = ([f32::INFINITY; 4], [u32::MAX; 4]);
                let mut m = hits.mask;
                for k in 0..4 {
                    if m != 0 {
                        let slot = m.trailing_zeros();
                        (keys[k], slots[k]) = (hits.t_enter[slot as usize], slot);
                        m &= m - 1;
                    }
                }
                sort_network(&mut keys, &mut slots);
                order[..4].copy_from_slice(&slots);
            }
            _ => {
                let (mut keys, mut slots) = sort_keys(hits);
                sort_network(&mut keys, &mut slots);
                *order = slots;
            }
        }
        n
    }
}

/// Sort keys: a hit child's entry distance and slot; a missed child's `+inf` and its slot plus
/// `W`, so that every missed child sorts after every hit one.
#[inline(always)]
pub fn sort_keys<const W: usize>(hits: &ChildHits<W>) -> ([f32; W], [u32; W]) {
    let keys = core::array::from_fn(|i| if hits.mask & (1 << i) != 0 { hits.t_enter[i] } else { f32::INFINITY });
    let slots = core::array::from_fn(|i| if hits.mask & (1 << i) != 0 { i as u32 } else { (i + W) as u32 });
    (keys, slots)
}

#[cfg(target_arch = "x86_64")]
mod sse {
    use super::ChildHits;
    use crate::intersect::{SlabRay, FAR_PAD};
    use crate::wide::node::WideNode;
    use core::arch::x86_64::{
        _mm_add_ps, _mm_and_ps, _mm_andnot_ps, _mm_castps_si128, _mm_castsi128_ps, _mm_cmple_ps, _mm_loadu_ps,
        _mm_max_ps, _mm_min_ps, _mm_movemask_ps, _mm_mul_ps, _mm_or_ps, _mm_set1_ps, _mm_srai_epi32, _mm_storeu_ps,
        _mm_sub_ps,
    };

    /// Four children per instruction, with the operations of [`SlabRay::hit_scalar`] in its
    /// order per lane: `maxps(x, acc)` is `keep_max(acc, x)` (it returns `acc` when `x` is NaN or
    /// equal), likewise `minps` and `keep_min`.
    #[inline(always)]
    #[allow(unused_unsafe)] // SSE2 intrinsics are safe to call from Rust 1.87 on; rust-version is older.
    pub(super) fn test<const W: usize>(node: &WideNode<W>, s: &SlabRay, tmin: f32, tmax: f32) -> ChildHits<W> {
        let mut out = ChildHits { t_enter: [f32::INFINITY; W], mask: 0 };
        let (o, inv) = (s.origin.to_array(), s.inv_dir.to_array());
        let mut lane = 0;
        while lane < W {
            // SAFETY: SSE2 is part of the x86_64 baseline; every load and store reads or writes
            // four floats inside arrays of `W` floats, `W` a multiple of four, at `lane <= W - 4`.
            unsafe {
                let splat = _mm_set1_ps;
                let (mut t_enter, mut t_exit) = (splat(tmin), splat(tmax));
                for a in 0..3 {
                    let lo = _mm_loadu_ps(node.lo[a].as_ptr().add(lane));
                    let hi = _mm_loadu_ps(node.hi[a].as_ptr().add(lane));
                    // Planes picked by the sign bit of `1 / d` (that of `d`, `1 / ±0 = ±inf`) as a
                    // mask, without a branch: scattered directions mispredicted one per axis.
                    let (oa, ia) = (splat(o[a]), splat(inv[a]));
                    let negative = _mm_castsi128_ps(_mm_srai_epi32::<31>(_mm_castps_si128(ia)));
                    let near = _mm_or_ps(_mm_and_ps(negative, hi), _mm_andnot_ps(negative, lo));
                    let far = _mm_or_ps(_mm_and_ps(negative, lo), _mm_andnot_ps(negative, hi));
                    let tn = _mm_mul_ps(_mm_sub_ps(near, oa), ia);
                    let tf = _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(far, oa), ia), splat(FAR_PAD));
                    t_enter = _mm_max_ps(tn, t_enter);
                    t_exit = _mm_min_ps(tf, t_exit);
                }
                let hit = _mm_cmple_ps(t_enter, _mm_add_ps(t_exit, splat(s.slack)));
                // Lanes that miss keep +inf, as the reference leaves them.
                let kept = _mm_or_ps(_mm_and_ps(hit, t_enter), _mm_andnot_ps(hit, splat(f32::INFINITY)));
                _mm_storeu_ps(out.t_enter.as_mut_ptr().add(lane), kept);
                out.mask |= (_mm_movemask_ps(hit) as u32) << lane;
            }
            lane += 4;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intersect::test_values::Rng;
    use glam::Vec3;

    fn node<const W: usize>(rng: &mut Rng) -> WideNode<W> {
        let mut n = WideNode::<W>::EMPTY;
        for i in 0..W {
            // Some slots stay empty; the rest get adversarial corners.
            if rng.adversarial() < 0.0 {
                continue;
            }
            let mut v = || rng.adversarial();
            let (lo, hi) = (Vec3::new(v(), v(), v()), Vec3::new(v(), v(), v()));
            n.set_child(i, lo, hi, super::super::node::WideChild::Node(i as u32));
        }
        n
    }

    fn fast_equals_reference<const W: usize>(seed: u64) {
        let mut rng = Rng(seed);
        let mut hits = 0;
        for _ in 0..50_000 {
            let (ray, slab) = rng.ray_and_slab();
            let n = node::<W>(&mut rng);
            let (f, r) =
                (FastKernel::test(&n, &slab, ray.tmin, ray.tmax), ReferenceKernel::test(&n, &slab, ray.tmin, ray.tmax));
            let bits = |h: &ChildHits<W>| (h.mask, h.t_enter.map(f32::to_bits));
            assert_eq!(bits(&f), bits(&r), "{ray:?} {n:?}");
            let (mut of, mut or) = ([0; W], [0; W]);
            let (nf, nr) = (FastKernel::order(&f, &mut of), ReferenceKernel::order(&r, &mut or));
            assert_eq!((nf, &of[..nf]), (nr, &or[..nr]));
            hits += r.mask.count_ones();
        }
        assert!(hits > 10_000, "only {hits} child hits");
    }

    #[test]
    fn fast_kernel_matches_the_reference_bit_for_bit_on_adversarial_values() {
        fast_equals_reference::<4>(0x9e37_79b9_7f4a_7c15);
        fast_equals_reference::<8>(0xd1b5_4a32_d192_ed03);
    }
}
