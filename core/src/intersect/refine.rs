//! Where the watertight test's `f32` distance may be off, and its recomputation in `f64`.
//!
//! The `f32` test's edge functions cancel on slivers seen at a slant, and `t`, a weighted mean of
//! the vertices' depths, then strays along the sliver's long depth range: hundreds of ulps off
//! the exact `t` on a grazing ray. [`needs_refine`] bounds that error to first order from values
//! the test has already computed; where the bound exceeds [`REFINE_ULPS`] ulps of `t`,
//! [`refine`] recomputes `t` and the barycentrics from the `f32` inputs in `f64`.
//!
//! Both must come out bit for bit the same on every backend:
//! - [`needs_refine`] is plain `f32` arithmetic in a fixed order, which the SSE block test and
//!   the WGSL kernel repeat operation for operation (its products fenced against contraction).
//! - [`refine`] multiplies only numbers that are `f32` values, so every product is exact in
//!   `f64` and a fused multiply-add (which a shader compiler may form) rounds as the separate
//!   operations do. Wider values are first split into two `f32` parts. It has no `f64` division:
//!   the quotients are taken in `f32`, correctly rounded on every backend.

/// The first-order error bound, in ulps of `t`, above which the test recomputes `t` in `f64`.
///
/// The bound is a worst case of about ten times the typical error, so this keeps the
/// recomputation to a few percent of the hits on slanted views (measured on the Sponza and kitchen
/// inside views), while every `t` left in `f32` is within this many ulps to first order.
pub const REFINE_ULPS: f32 = 256.0;

/// `lhs > REFINE_SCALE * |t * det|` flags a hit: with `lhs` the edge functions' error terms
/// weighted by the depths (see `needs_refine` in this module), the bound is
/// `2ε·lhs/|det| + 8ε|t|`, and `(REFINE_ULPS - 8) / 2` moves both `ε` factors and the constant
/// part to this side. The wgpu kernels get its bits from here.
pub const REFINE_SCALE: f32 = (REFINE_ULPS - 8.0) / 2.0;

/// Whether the `f32` hit may be more than [`REFINE_ULPS`] ulps off, to first order.
///
/// `rel` are the vertices relative to the origin in ray axis order (`kx, ky, kz`), `xy` their
/// sheared 2D coordinates, `z` their depths (`sz * rel[2]`), `t` and `det` the test's. The
/// terms, with `ε = 2^-24`:
/// - a sheared coordinate of vertex `i` is off by at most `2ε·m_i`,
///   `m_i = |x_i| + |y_i| + 2|z_i|` of its relative position (the subtraction, `sx`'s rounding,
///   the product and the shear's own subtraction, with `|sx|, |sy| ≤ 1`);
/// - so an edge function, say `u = c_x b_y - c_y b_x`, is off by at most
///   `2ε(m_b s_c + m_c s_b + s_b s_c)` with `s_i = |x_i| + |y_i|` of the sheared vertex (the last
///   term its two products' and its difference's roundings);
/// - `t = Σ u_i z_i / Σ u_i` moves by `Σ δu_i (z_i − t) / det`, and the depths', the sums' and the
///   division's roundings add `8ε|t|` where every vertex lies ahead of the origin (the depths
///   have one sign).
#[inline(always)]
pub(crate) fn needs_refine(rel: [[f32; 3]; 3], xy: [[f32; 2]; 3], z: [f32; 3], t: f32, det: f32) -> bool {
    let m = rel.map(|p| (p[0].abs() + p[1].abs()) + (p[2].abs() + p[2].abs()));
    let s = xy.map(|p| p[0].abs() + p[1].abs());
    let (ma, mb, mc) = (m[0], m[1], m[2]);
    let (sa, sb, sc) = (s[0], s[1], s[2]);
    let eu = (mb * sc + mc * sb) + sb * sc;
    let ev = (mc * sa + ma * sc) + sc * sa;
    let ew = (ma * sb + mb * sa) + sa * sb;
    let lhs = (eu * (z[0] - t).abs() + ev * (z[1] - t).abs()) + ew * (z[2] - t).abs();
    lhs > REFINE_SCALE * (t * det).abs()
}

/// A refined hit: `t` and the barycentrics of the second and third vertex.
pub(crate) type Refined = (f32, f32, f32);

/// `x` as the sum of two `f32`s (exact where `x` fits in 48 bits, else to 2^-48 of `x`).
#[inline(always)]
fn split(x: f64) -> (f64, f64) {
    let hi = x as f32;
    (hi as f64, (x - hi as f64) as f32 as f64)
}

/// `p * q` of two split numbers, the products of parts only (each exact): `pq` to about 2^-47.
#[inline(always)]
fn mul2(p: (f64, f64), q: (f64, f64)) -> f64 {
    p.0 * q.0 + (p.0 * q.1 + p.1 * q.0)
}

/// `p.x q.y − p.y q.x` of split sheared coordinates, the leading products first.
#[inline(always)]
fn edge(p: [(f64, f64); 2], q: [(f64, f64); 2]) -> f64 {
    let lead = p[0].0 * q[1].0 - p[1].0 * q[0].0;
    lead + ((p[0].0 * q[1].1 + p[0].1 * q[1].0) - (p[1].0 * q[0].1 + p[1].1 * q[0].0))
}

/// `2^-e` for a normal `x` with `2^e <= |x| < 2^(e+1)`, else 1: the product of two `f32` powers
/// of two (each within the normal range), exact in `f64`, so the WGSL kernel can form the same
/// value without building an `f64` from bits.
#[inline(always)]
fn inverse_scale(x: f32) -> f64 {
    let e = ((x.to_bits() >> 23) & 0xff) as i32;
    if e == 0 || e == 255 {
        return 1.0;
    }
    let k = 127 - e;
    let half = k.div_euclid(2);
    let pow2 = |k: i32| f32::from_bits(((k + 127) as u32) << 23) as f64;
    pow2(half) * pow2(k - half)
}

/// The hit recomputed in `f64` from the `f32` inputs: `origin` and `dir` in ray axis order
/// (`kx, ky, kz`, the same permutation as the test's), the vertices `v` as stored. `None` where a
/// value leaves the `f32` range (the caller keeps its `f32` hit).
///
/// The ray is sheared without dividing: `X = dz·x − dx·z` is `dz` times the sheared coordinate,
/// so the edge functions come out `dz²` times the test's and `t = Σ U_i z_i / (dz Σ U_i)`.
///
/// The direction is first scaled by a power of two so that `1 <= |dz| < 2` (exact, and the
/// distance is scaled back at the end, exactly where it stays normal): with `dz` far from 1 (the
/// backends scale scenes to unit size and the directions with them, `2^-39` for a scene of
/// size 1e12) the denominator `dz³` times the test's would otherwise come out subnormal in `f32`
/// and lose most of its bits.
#[inline(never)]
pub(crate) fn refine(origin: [f32; 3], dir: [f32; 3], k: [usize; 3], v: [&[f32; 3]; 3]) -> Option<Refined> {
    let scale = inverse_scale(dir[2]);
    // Each still an f32 significand, so the products below stay exact.
    let [dx, dy, dz] = dir.map(|x| f64::from(x) * scale);
    // The relative position, exact in f64 but for exponents far apart, as two f32 parts.
    let rel = v.map(|p| core::array::from_fn::<_, 3, _>(|i| split(p[k[i]] as f64 - origin[i] as f64)));
    let shear = |p: &[(f64, f64); 3]| {
        let x = ((dz * p[0].0 - dx * p[2].0) + dz * p[0].1) - dx * p[2].1;
        let y = ((dz * p[1].0 - dy * p[2].0) + dz * p[1].1) - dy * p[2].1;
        [split(x), split(y)]
    };
    let [a, b, c] = [shear(&rel[0]), shear(&rel[1]), shear(&rel[2])];
    let u = edge(c, b);
    let w_ = edge(b, a);
    let v_ = edge(a, c);
    // The f32 test decided the ray meets the triangle; where the f64 edge functions disagree (a
    // ray nearly in the plane), the plane's f64 crossing may lie far outside the triangle and
    // its box, so the f32 hit stands.
    if (u < 0.0 || v_ < 0.0 || w_ < 0.0) && (u > 0.0 || v_ > 0.0 || w_ > 0.0) {
        return None;
    }
    let det = (u + v_) + w_;
    let num = (mul2(split(u), rel[0][2]) + mul2(split(v_), rel[1][2])) + mul2(split(w_), rel[2][2]);
    let d = split(det);
    let den = d.0 * dz + d.1 * dz;
    let [num, den, det, v_, w_] = [num, den, det, v_, w_].map(|x| x as f32);
    if ![num, den, det, v_, w_].iter().all(|x| x.is_finite()) || den == 0.0 || det == 0.0 {
        return None;
    }
    // `t` along the scaled direction, times the scale: `t` along the ray.
    let t = (f64::from(num / den) * scale) as f32;
    Some((t, v_ / det, w_ / det))
}
