//! `f32` values as integers: every finite `f32` is `m * 2^e` with `e >= -149`, so times `2^149`
//! it is an integer. Scaling every input by the same power of two leaves `t` unchanged.

use num_bigint::BigInt;

/// The power of two every coordinate is multiplied by (the smallest subnormal is `2^-149`).
pub const SHIFT: i32 = 149;

/// `x * 2^149` as an integer; `None` for a NaN or an infinity.
pub fn to_int(x: f32) -> Option<BigInt> {
    if !x.is_finite() {
        return None;
    }
    let bits = x.to_bits();
    let exp = ((bits >> 23) & 0xff) as i32;
    let frac = (bits & 0x7f_ffff) as i64;
    // A normal number is (2^23 + frac) * 2^(exp - 150); a subnormal is frac * 2^-149.
    let (m, e) = if exp == 0 { (frac, -149) } else { (frac | 0x80_0000, exp - 150) };
    let m = if bits >> 31 == 1 { -m } else { m };
    Some(BigInt::from(m) << (e + SHIFT) as usize)
}

/// A point as three integers ([`to_int`]).
pub fn to_int3(p: [f32; 3]) -> Option<[BigInt; 3]> {
    Some([to_int(p[0])?, to_int(p[1])?, to_int(p[2])?])
}

/// `x` (an `f32`) as the fraction `num / 2^shift` with `shift >= 0`, exactly.
pub fn as_fraction(x: f32) -> Option<(BigInt, u32)> {
    Some((to_int(x)?, SHIFT as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_scale_exactly() {
        assert_eq!(to_int(1.0), Some(BigInt::from(1) << 149usize));
        assert_eq!(to_int(-0.5), Some(-(BigInt::from(1) << 148usize)));
        assert_eq!(to_int(f32::from_bits(1)), Some(BigInt::from(1)));
        assert_eq!(to_int(0.0), Some(BigInt::from(0)));
        assert_eq!(to_int(-0.0), Some(BigInt::from(0)));
        assert_eq!(to_int(f32::NAN), None);
        let max = to_int(f32::MAX).unwrap();
        assert_eq!(max, BigInt::from((1u64 << 24) - 1) << (104usize + 149));
    }
}
