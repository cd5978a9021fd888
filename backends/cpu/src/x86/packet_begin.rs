//! A wide packet's lanes made eight rays at a time: the rays as given, turned from rows (one ray's
//! 32 bytes) into columns (one field of eight rays) by an 8x8 transpose, then each field's setup
//! for all eight lanes per operation. Made ray by ray, the setup (the acceptance test, the
//! reciprocal direction, the slack, the box interval, the packet's bounds) and the copies of each
//! ray's context into its lane were about half the instructions of a kitchen shadow ray that its
//! packet answers at its first leaf
//! (`docs/notes/*-benchmarks-packet-lanes.md`, "Packet lanes made eight rays at a time").
//!
//! Each lane is the scalar setup's operations in their order (`Ray::is_traceable`,
//! `SlabRay::with_slack`, `SlabRay::widen`), so the lanes equal
//! [`PacketKernel::begin`](raytrail_core::wide::packet::PacketKernel::begin)'s bit for bit; lanes
//! without an accepted ray hold what `PacketLanes::new` put there.

use crate::x86::lanes::{horizontal, Fold};
use raytrail_core::intersect::{RELIABLE_LIMIT, SLACK_SCALE};
use raytrail_core::wide::packet::PacketLanes;
use raytrail_core::Ray;
use std::arch::x86_64::{
    __m256, _mm256_add_ps, _mm256_and_ps, _mm256_andnot_ps, _mm256_blendv_ps, _mm256_cmp_ps, _mm256_div_ps,
    _mm256_loadu_ps, _mm256_max_ps, _mm256_min_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_or_ps,
    _mm256_permute2f128_ps, _mm256_set1_ps, _mm256_setzero_ps, _mm256_shuffle_ps, _mm256_storeu_ps, _mm256_sub_ps,
    _mm256_unpackhi_ps, _mm256_unpacklo_ps, _CMP_EQ_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _CMP_NEQ_UQ,
};

/// The packet's bounds over its accepted lanes so far, eight partial bounds per register.
struct Bounds {
    origin: [(__m256, __m256); 3],
    inv_dir: [(__m256, __m256); 3],
    t_lo_min: __m256,
    slack_max: __m256,
    t_hi_max: __m256,
}

/// [`PacketKernel::begin`](raytrail_core::wide::packet::PacketKernel::begin) for `N` a multiple of
/// 8, eight lanes per operation: `lanes` must be fresh from `PacketLanes::new`.
///
/// # Safety
/// The processor must run the AVX2 path ([`crate::x86::available`]); `N` must be a multiple of 8.
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
#[inline]
pub(crate) unsafe fn begin<const N: usize>(rays: &[Ray], scene_scale: f32, lanes: &mut PacketLanes<N>) {
    let n = rays.len().min(N).min(64);
    let s = _mm256_set1_ps;
    let (inf, zero) = (s(f32::INFINITY), _mm256_setzero_ps());
    let mut b = Bounds {
        origin: [(inf, s(f32::NEG_INFINITY)); 3],
        inv_dir: [(inf, s(f32::NEG_INFINITY)); 3],
        t_lo_min: inf,
        slack_max: zero,
        t_hi_max: s(f32::NEG_INFINITY),
    };
    for g in 0..n.div_ceil(8) {
        let at = 8 * g;
        // A row is one `Ray` (`repr(C)`: origin, tmin, direction, tmax); a row past the last ray
        // is all zeros: a zero direction, which no lane accepts.
        let row = |k: usize| if at + k < n { _mm256_loadu_ps(rays.as_ptr().add(at + k).cast::<f32>()) } else { zero };
        let [ox, oy, oz, tmin, dx, dy, dz, tmax] =
            transpose([row(0), row(1), row(2), row(3), row(4), row(5), row(6), row(7)]);
        let accepted = lanes_in(&mut b, [ox, oy, oz], [dx, dy, dz], tmin, tmax, scene_scale, at, lanes);
        lanes.traced |= u64::from(accepted) << at;
    }
    let r = &mut lanes.rays;
    for a in 0..3 {
        r.origin_range[a] = (horizontal(b.origin[a].0, Fold::Min), horizontal(b.origin[a].1, Fold::Max));
        r.inv_range[a] = (horizontal(b.inv_dir[a].0, Fold::Min), horizontal(b.inv_dir[a].1, Fold::Max));
    }
    r.t_lo_min = horizontal(b.t_lo_min, Fold::Min);
    r.slack_max = horizontal(b.slack_max, Fold::Max);
    r.t_hi_max = horizontal(b.t_hi_max, Fold::Max);
}

/// The lanes `at..at + 8` from eight rays by field: each accepted ray's setup stored in its lane
/// and folded into the bounds; returns the accepted lanes (bit `k` for lane `at + k`).
///
/// # Safety
/// As [`begin`]; `at + 8 <= N`.
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
#[inline]
#[allow(clippy::too_many_arguments)]
unsafe fn lanes_in<const N: usize>(
    b: &mut Bounds,
    o: [__m256; 3],
    d: [__m256; 3],
    tmin: __m256,
    tmax: __m256,
    scene_scale: f32,
    at: usize,
    lanes: &mut PacketLanes<N>,
) -> u32 {
    let s = _mm256_set1_ps;
    let (inf, ninf, zero) = (s(f32::INFINITY), s(f32::NEG_INFINITY), _mm256_setzero_ps());
    let abs = |x: __m256| _mm256_andnot_ps(s(-0.0), x);
    // `Ray::is_traceable`: `x * 0 + y * 0 == 0` for finite `x` and `y`, a nonzero direction
    // component, and `tmin <= tmax` (false where either is NaN).
    let mut ok = _mm256_cmp_ps::<_CMP_LE_OQ>(tmin, tmax);
    let mut nonzero = zero;
    for a in 0..3 {
        let finite = _mm256_add_ps(_mm256_mul_ps(o[a], zero), _mm256_mul_ps(d[a], zero));
        ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_EQ_OQ>(finite, zero));
        nonzero = _mm256_or_ps(nonzero, _mm256_cmp_ps::<_CMP_NEQ_UQ>(d[a], zero));
    }
    let ok = _mm256_and_ps(ok, nonzero);
    // `SlabRay::with_slack`: IEEE `1 / d`, `reach = scene_scale + max |o|`, `reach * min |1 / d|`.
    let inv = [_mm256_div_ps(s(1.0), d[0]), _mm256_div_ps(s(1.0), d[1]), _mm256_div_ps(s(1.0), d[2])];
    let reach = _mm256_add_ps(s(scene_scale), _mm256_max_ps(_mm256_max_ps(abs(o[0]), abs(o[1])), abs(o[2])));
    let reach_per_d = _mm256_mul_ps(reach, _mm256_min_ps(_mm256_min_ps(abs(inv[0]), abs(inv[1])), abs(inv[2])));
    let reliable =
        _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_mul_ps(_mm256_mul_ps(reach, reach), reach_per_d), s(RELIABLE_LIMIT));
    let slack = _mm256_blendv_ps(inf, _mm256_mul_ps(reach_per_d, s(SLACK_SCALE)), reliable);
    // `begin_slab` keeps a ray only where its slack is finite.
    let ok = _mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_LT_OQ>(abs(slack), inf));
    // Accepted lanes get their values, the others `PacketLanes::new`'s.
    let or = |empty: __m256, x: __m256| _mm256_blendv_ps(empty, x, ok);
    let st = |a: &mut [f32; N], x: __m256| _mm256_storeu_ps(a.as_mut_ptr().add(at), x);
    let r = &mut lanes.rays;
    for a in 0..3 {
        st(&mut r.origin[a], or(zero, o[a]));
        st(&mut r.inv_dir[a], or(zero, inv[a]));
        st(&mut lanes.dir[a], or(zero, d[a]));
        b.origin[a] = (_mm256_min_ps(b.origin[a].0, or(inf, o[a])), _mm256_max_ps(b.origin[a].1, or(ninf, o[a])));
        b.inv_dir[a] =
            (_mm256_min_ps(b.inv_dir[a].0, or(inf, inv[a])), _mm256_max_ps(b.inv_dir[a].1, or(ninf, inv[a])));
    }
    // `SlabRay::widen` over `[tmin, tmax]`: no answer yet, so the culling distance is `tmax`.
    let t_lo = or(inf, _mm256_sub_ps(tmin, slack));
    let t_hi = or(ninf, _mm256_add_ps(tmax, slack));
    let slack = or(zero, slack);
    st(&mut r.t_lo, t_lo);
    st(&mut r.t_hi, t_hi);
    st(&mut r.slack, slack);
    st(&mut lanes.tmin, or(zero, tmin));
    st(&mut lanes.tmax, or(zero, tmax));
    st(&mut lanes.limit, or(zero, tmax));
    b.t_lo_min = _mm256_min_ps(b.t_lo_min, t_lo);
    b.slack_max = _mm256_max_ps(b.slack_max, slack);
    b.t_hi_max = _mm256_max_ps(b.t_hi_max, t_hi);
    _mm256_movemask_ps(ok) as u32
}

/// Rows to columns: lane `k` of column `j` is lane `j` of row `k`.
///
/// # Safety
/// The processor must support AVX.
#[target_feature(enable = "avx")]
#[inline]
unsafe fn transpose(r: [__m256; 8]) -> [__m256; 8] {
    // Pairs of rows interleaved, then quarters of columns gathered, each 128-bit half on its own.
    let lo = |a: usize, b: usize| _mm256_unpacklo_ps(r[a], r[b]);
    let hi = |a: usize, b: usize| _mm256_unpackhi_ps(r[a], r[b]);
    let t = [lo(0, 1), hi(0, 1), lo(2, 3), hi(2, 3), lo(4, 5), hi(4, 5), lo(6, 7), hi(6, 7)];
    let u = [
        _mm256_shuffle_ps::<0x44>(t[0], t[2]),
        _mm256_shuffle_ps::<0xee>(t[0], t[2]),
        _mm256_shuffle_ps::<0x44>(t[1], t[3]),
        _mm256_shuffle_ps::<0xee>(t[1], t[3]),
        _mm256_shuffle_ps::<0x44>(t[4], t[6]),
        _mm256_shuffle_ps::<0xee>(t[4], t[6]),
        _mm256_shuffle_ps::<0x44>(t[5], t[7]),
        _mm256_shuffle_ps::<0xee>(t[5], t[7]),
    ];
    // Columns 0-3 are the low halves of rows 0-3 and 4-7; columns 4-7 the high halves.
    [
        _mm256_permute2f128_ps::<0x20>(u[0], u[4]),
        _mm256_permute2f128_ps::<0x20>(u[1], u[5]),
        _mm256_permute2f128_ps::<0x20>(u[2], u[6]),
        _mm256_permute2f128_ps::<0x20>(u[3], u[7]),
        _mm256_permute2f128_ps::<0x31>(u[0], u[4]),
        _mm256_permute2f128_ps::<0x31>(u[1], u[5]),
        _mm256_permute2f128_ps::<0x31>(u[2], u[6]),
        _mm256_permute2f128_ps::<0x31>(u[3], u[7]),
    ]
}

#[cfg(test)]
mod tests {
    use super::begin;
    use crate::test_rng::Rng;
    use raytrail_core::method::Query;
    use raytrail_core::wide::packet::{PacketKernel, PacketLanes, ReferencePacketKernel};
    use raytrail_core::Ray;

    /// A float for the adversarial rays: mostly ordinary, sometimes zero of either sign, infinite,
    /// NaN, or so large or so small that the ray's slack overflows.
    fn component(rng: &mut Rng) -> f32 {
        match rng.next() % 40 {
            0 => f32::NAN,
            1 => f32::INFINITY,
            2 => f32::NEG_INFINITY,
            3 => 1e30,
            4 => -1e-30,
            5 => 3e-39,
            _ => rng.value(),
        }
    }

    /// Every lane and every bound `begin` makes equals the ray-by-ray setup's, on packets of 0 to
    /// 32 rays with zero, infinite and NaN components, reversed intervals and unreliable slacks.
    #[test]
    fn lanes_made_eight_at_once_are_each_rays_own() {
        if crate::x86::lacks_avx2_for("packet begin") {
            return;
        }
        let mut rng = Rng(0x6a09_e667_f3bc_c909);
        let (mut accepted, mut turned_away) = (0u32, 0u32);
        for round in 0..20_000 {
            let n = round % 33;
            let scene_scale = [1.0, 8.0, 1e12][round % 3];
            let rays: Vec<Ray> = (0..n)
                .map(|_| {
                    let mut c = || component(&mut rng);
                    let (origin, dir) = ([c(), c(), c()], [c(), c(), c()]);
                    let tmin = [0.0, 0.5, -1.0, f32::NAN, 2.0, 1.0][(rng.next() % 6) as usize];
                    let tmax = [f32::INFINITY, 1.0, 3.0, f32::NAN][(rng.next() % 4) as usize];
                    Ray { origin, tmin, dir, tmax }
                })
                .collect();
            let query = if round % 2 == 0 { Query::Closest } else { Query::Any };
            let mut want = PacketLanes::<32>::new(query);
            ReferencePacketKernel::begin(&rays, scene_scale, &mut want);
            let mut got = PacketLanes::<32>::new(query);
            // SAFETY: AVX2 checked above; 32 is a multiple of 8.
            unsafe { begin(&rays, scene_scale, &mut got) };
            let bits = |l: &PacketLanes<32>| {
                let r = &l.rays;
                let mut v: Vec<u32> = Vec::new();
                for a in 0..3 {
                    v.extend(r.origin[a].iter().chain(&r.inv_dir[a]).chain(&l.dir[a]).map(|x| x.to_bits()));
                }
                for f in [&r.t_lo, &r.t_hi, &r.slack, &l.tmin, &l.tmax, &l.limit] {
                    v.extend(f.iter().map(|x| x.to_bits()));
                }
                v
            };
            assert_eq!(got.traced, want.traced, "round {round}: {rays:?}");
            assert_eq!(bits(&got), bits(&want), "round {round}: {rays:?}");
            // Bounds are compared by value: a fold may keep either zero of a tie.
            let bounds = |l: &PacketLanes<32>| {
                let r = &l.rays;
                (r.origin_range, r.inv_range, r.t_lo_min, r.slack_max, r.t_hi_max)
            };
            assert_eq!(bounds(&got), bounds(&want), "round {round}: {rays:?}");
            accepted += want.traced.count_ones();
            turned_away += n as u32 - want.traced.count_ones();
        }
        assert!(accepted > 50_000 && turned_away > 50_000, "{accepted} accepted, {turned_away} turned away");
    }
}
