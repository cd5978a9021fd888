//! Both child boxes of a BVH2 node in one slab test.
//!
//! The Aila-Laine node stores the two boxes as `left_xy`, `right_xy` and `z` quadruples, laid out
//! for exactly this: three 4-wide loads bring in all twelve planes. The 4-wide path evaluates the
//! same IEEE operations as [`SlabRay::hit`], lane by lane and in the same order, so its decisions
//! and distances are bit-identical to two scalar tests (the unit tests below check that). The
//! scalar path stays beside it for other targets and as the reference.

use super::{BoxHit, SlabRay};
use crate::bvh2::BinaryNode;

/// The per-ray constants of the two-box slab test ([`SlabPair::hit_pair`]).
#[derive(Clone, Copy, Debug)]
pub struct SlabPair {
    #[cfg(target_arch = "x86_64")]
    sse: sse::Constants,
    #[cfg(not(target_arch = "x86_64"))]
    slab: SlabRay,
}

impl SlabPair {
    /// The constants of `slab` (its origin, reciprocal direction, direction signs and slack).
    #[inline]
    pub fn new(slab: &SlabRay) -> Self {
        Self {
            #[cfg(target_arch = "x86_64")]
            sse: sse::Constants::new(slab),
            #[cfg(not(target_arch = "x86_64"))]
            slab: *slab,
        }
    }

    /// `[left, right]`: what [`SlabRay::hit`] returns for each child box of `node` over
    /// `[tmin, tmax]`, bit for bit.
    #[inline(always)]
    pub fn hit_pair(&self, node: &BinaryNode, tmin: f32, tmax: f32) -> [Option<BoxHit>; 2] {
        #[cfg(target_arch = "x86_64")]
        return self.sse.hit_pair(node, tmin, tmax);
        #[cfg(not(target_arch = "x86_64"))]
        return hit_pair_scalar(&self.slab, node, tmin, tmax);
    }
}

/// The scalar reference: [`SlabRay::hit_scalar`] on each child box in turn.
#[inline(always)]
pub fn hit_pair_scalar(slab: &SlabRay, node: &BinaryNode, tmin: f32, tmax: f32) -> [Option<BoxHit>; 2] {
    let (l0, l1) = node.child_bounds(0);
    let (r0, r1) = node.child_bounds(1);
    [slab.hit_scalar(l0, l1, tmin, tmax), slab.hit_scalar(r0, r1, tmin, tmax)]
}

/// The SSE2 path (every x86_64 CPU has SSE2, so no run-time detection is needed).
///
/// Why: the two scalar slab tests were the largest item of a flat profile, about 80 scalar
/// instructions per node with spills (a `maxss`/`minss` chain and a sign-dependent plane pick per
/// axis and box); this is about 35 SSE instructions for both boxes, all in registers.
///
/// Lanes hold `[left near, left far, right near, right far]` for one axis at a time. Two exact
/// rewrites let one `maxps` chain do both the entry (max) and the exit (min) accumulations:
/// - far distances are multiplied by `-FAR_PAD` instead of `FAR_PAD` (and near ones by `1`):
///   negation commutes with round-to-nearest, so a far lane holds exactly `-(d * FAR_PAD)`;
/// - `keep_min(acc, x) = -keep_max(-acc, -x)`, bit for bit, NaN included.
///
/// `keep_max(acc, x)` (keep `acc` unless `x > acc`) is `_mm_max_ps(x, acc)`: `maxps` returns its
/// second operand when either is NaN or both are equal. The chain runs over x, then y, then z,
/// starting from `[tmin, -tmax, tmin, -tmax]`, as the scalar test does.
#[cfg(target_arch = "x86_64")]
mod sse {
    use super::{BoxHit, SlabRay};
    use crate::bvh2::BinaryNode;
    use crate::intersect::FAR_PAD;
    use core::arch::x86_64::{
        __m128, _mm_and_ps, _mm_andnot_ps, _mm_castsi128_ps, _mm_cmple_ps, _mm_cvtss_f32, _mm_max_ps, _mm_movemask_ps,
        _mm_mul_ps, _mm_or_ps, _mm_set1_epi32, _mm_set1_ps, _mm_setr_ps, _mm_shuffle_ps, _mm_sub_ps, _mm_unpacklo_ps,
    };

    /// Per-ray constants, arranged for the lanes of a node's `xy` and `z` quadruples.
    #[derive(Clone, Copy, Debug)]
    pub(super) struct Constants {
        /// `[ox, ox, oy, oy]`, matching `lo.x, hi.x, lo.y, hi.y`.
        origin_xy: __m128,
        /// `[1/dx, 1/dx, 1/dy, 1/dy]`.
        inv_xy: __m128,
        /// Per plane of `lo.x, hi.x, lo.y, hi.y`: `1` for a near plane, `-FAR_PAD` for a far one.
        scale_xy: __m128,
        /// `oz` in every lane.
        origin_z: __m128,
        /// `1/dz` in every lane.
        inv_z: __m128,
        /// Per plane of `lo.z, hi.z, lo.z, hi.z`, as `scale_xy`.
        scale_z: __m128,
        /// Per axis: all bits set where the direction's sign bit is (the near plane is `hi`).
        swap: [__m128; 3],
        /// The ray's slack in every lane.
        slack: __m128,
    }

    /// `(near, far)` scale factors of the `lo` and `hi` planes of an axis.
    fn scales(negative: bool) -> (f32, f32) {
        if negative {
            (-FAR_PAD, 1.0)
        } else {
            (1.0, -FAR_PAD)
        }
    }

    impl Constants {
        /// The constants of `slab`.
        #[inline]
        #[allow(unused_unsafe)] // SSE2 intrinsics are safe to call from Rust 1.87 on; rust-version is older.
        pub(super) fn new(slab: &SlabRay) -> Self {
            let (o, inv, neg) = (slab.origin, slab.inv_dir, slab.negative);
            let (sx0, sx1) = scales(neg[0]);
            let (sy0, sy1) = scales(neg[1]);
            let (sz0, sz1) = scales(neg[2]);
            // SAFETY: SSE2 is part of the x86_64 baseline; these intrinsics only compute.
            unsafe {
                let mask = |n: bool| _mm_castsi128_ps(_mm_set1_epi32(-(n as i32)));
                Self {
                    origin_xy: _mm_setr_ps(o.x, o.x, o.y, o.y),
                    inv_xy: _mm_setr_ps(inv.x, inv.x, inv.y, inv.y),
                    scale_xy: _mm_setr_ps(sx0, sx1, sy0, sy1),
                    origin_z: _mm_set1_ps(o.z),
                    inv_z: _mm_set1_ps(inv.z),
                    scale_z: _mm_setr_ps(sz0, sz1, sz0, sz1),
                    swap: [mask(neg[0]), mask(neg[1]), mask(neg[2])],
                    slack: _mm_set1_ps(slab.slack),
                }
            }
        }

        /// Both child boxes of `node` over `[tmin, tmax]`; see the module documentation.
        #[inline(always)]
        #[allow(unused_unsafe)] // SSE2 intrinsics are safe to call from Rust 1.87 on; rust-version is older.
        pub(super) fn hit_pair(&self, node: &BinaryNode, tmin: f32, tmax: f32) -> [Option<BoxHit>; 2] {
            // The node's quadruples, read in place (bytemuck: a safe, unaligned 16-byte load).
            let left: __m128 = bytemuck::cast(node.left_xy);
            let right: __m128 = bytemuck::cast(node.right_xy);
            let z: __m128 = bytemuck::cast(node.z);
            // SAFETY: SSE2 is part of the x86_64 baseline; these intrinsics only compute.
            unsafe {
                // (plane - origin) * inv_dir, then * 1 (near) or * -FAR_PAD (far), as in `SlabRay::hit`.
                let dist =
                    |p: __m128, o: __m128, inv: __m128, s: __m128| _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(p, o), inv), s);
                let a = dist(left, self.origin_xy, self.inv_xy, self.scale_xy);
                let b = dist(right, self.origin_xy, self.inv_xy, self.scale_xy);
                let c = dist(z, self.origin_z, self.inv_z, self.scale_z);
                // Per axis `[left lo, left hi, right lo, right hi]`, swapped to near-then-far where
                // the direction is negative (`select` on the per-ray mask: no branch).
                let select = |m: __m128, yes: __m128, no: __m128| _mm_or_ps(_mm_and_ps(m, yes), _mm_andnot_ps(m, no));
                let x =
                    select(self.swap[0], _mm_shuffle_ps::<0b00_01_00_01>(a, b), _mm_shuffle_ps::<0b01_00_01_00>(a, b));
                let y =
                    select(self.swap[1], _mm_shuffle_ps::<0b10_11_10_11>(a, b), _mm_shuffle_ps::<0b11_10_11_10>(a, b));
                let z = select(self.swap[2], _mm_shuffle_ps::<0b10_11_00_01>(c, c), c);
                // `[tmin, -tmax, tmin, -tmax]`, then keep_max/keep_min over x, y, z.
                let mut acc = _mm_unpacklo_ps(_mm_set1_ps(tmin), _mm_set1_ps(-tmax));
                acc = _mm_max_ps(x, acc);
                acc = _mm_max_ps(y, acc);
                acc = _mm_max_ps(z, acc);
                // `t_enter <= t_exit + slack`, with `t_exit + slack = slack - (-t_exit)` exactly.
                let exit_slack = _mm_sub_ps(self.slack, acc);
                let hits = _mm_movemask_ps(_mm_cmple_ps(acc, _mm_shuffle_ps::<0b11_11_01_01>(exit_slack, exit_slack)));
                let lane = |i: usize| -> f32 {
                    let v = match i {
                        0 => acc,
                        1 => _mm_shuffle_ps::<0b01_01_01_01>(acc, acc),
                        2 => _mm_shuffle_ps::<0b10_10_10_10>(acc, acc),
                        _ => _mm_shuffle_ps::<0b11_11_11_11>(acc, acc),
                    };
                    _mm_cvtss_f32(v)
                };
                let child = |i: usize| -> Option<BoxHit> {
                    (hits & (1 << (2 * i)) != 0).then(|| BoxHit { t_enter: lane(2 * i), t_exit: -lane(2 * i + 1) })
                };
                [child(0), child(1)]
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intersect::test_values::{same, Rng};

    #[test]
    fn matches_the_scalar_test_bit_for_bit() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut hits = 0;
        for _ in 0..200_000 {
            let (ray, slab) = rng.ray_and_slab();
            let mut v = || rng.adversarial();
            let node = BinaryNode {
                left_xy: [v(), v(), v(), v()],
                right_xy: [v(), v(), v(), v()],
                z: [v(), v(), v(), v()],
                ..bytemuck::Zeroable::zeroed()
            };
            let (tmin, tmax) = (ray.tmin, ray.tmax);
            let fast = SlabPair::new(&slab).hit_pair(&node, tmin, tmax);
            let reference = hit_pair_scalar(&slab, &node, tmin, tmax);
            assert!(
                same(fast[0], reference[0]) && same(fast[1], reference[1]),
                "{ray:?} {node:?}: {fast:?} != {reference:?}"
            );
            hits += reference.iter().flatten().count();
        }
        // The cases must exercise hits as well as misses.
        assert!(hits > 20_000, "only {hits} box hits");
    }
}
