//! Scenes far from unit size are prepared scaled by a power of two, so that their largest
//! coordinate magnitude lies in `[0.5, 1)`.
//!
//! Why: the triangle test forms products of order `reach^3 / |d|`, which overflow for scenes
//! around `1e13` and beyond and lose bits to subnormals around `1e-13` and below (see
//! [`crate::intersect::RayContext::is_reliable`]). Multiplying every coordinate by a power of
//! two is exact in binary floating point as long as nothing overflows or turns subnormal, and a
//! ray scaled by the same power (origin and direction both) gives bit for bit the same `t`: every
//! quantity of the tests scales by a power of two that cancels in `t`. The rays are scaled where a
//! batch starts ([`super::FramedRays`]); hits need no change.

use crate::bvh2::{Bvh2, Bvh2Node};
use crate::geometry::Triangle;
use crate::scene::Scene;
use crate::{Aabb, Error};
use alloc::vec::Vec;
use glam::Vec3;

/// Scenes whose largest coordinate magnitude lies in `[2^-LIMIT, 2^LIMIT]` are left as they are
/// (the tests' products are far from the float range there, and a scene the project has always
/// traced keeps every bit of its results, enumerations included).
pub const UNSCALED_LIMIT: i32 = 16;

/// `x * 2^e` for a power of two that does not overflow `f32` (split in two steps so that both
/// factors are normal `f32`s).
#[inline]
pub fn scale_pow2(x: f32, e: i32) -> f32 {
    let half = e / 2;
    x * pow2(half) * pow2(e - half)
}

/// `2^e` for `e` in `-126..=127`.
#[inline]
fn pow2(e: i32) -> f32 {
    f32::from_bits(((e.clamp(-126, 127) + 127) as u32) << 23)
}

/// The exponent `k` with `scale / 2^k` in `[0.5, 1)`, or 0 where the scene is left unscaled.
pub fn exponent_for(scale: f32) -> i32 {
    if !scale.is_finite() || scale == 0.0 {
        return 0;
    }
    let lo = f32::from_bits(((127 - UNSCALED_LIMIT) as u32) << 23);
    let hi = f32::from_bits(((127 + UNSCALED_LIMIT) as u32) << 23);
    if (lo..=hi).contains(&scale) {
        return 0;
    }
    exponent_of(scale)
}

/// The exponent `k` with `x / 2^k` in `[0.5, 1)` for a finite nonzero `x` (0 otherwise).
pub fn exponent_of(x: f32) -> i32 {
    if !x.is_finite() || x == 0.0 {
        return 0;
    }
    // Subnormals have no exponent bits of their own: count their leading zeros.
    let bits = x.abs().to_bits();
    let biased = (bits >> 23) as i32;
    if biased == 0 {
        -126 - ((bits & 0x7f_ffff).leading_zeros() as i32 - 9)
    } else {
        biased - 126
    }
}

/// Whether `x * 2^-k` loses nothing (no bits below the subnormal range, no overflow).
fn exact(x: f32, k: i32) -> bool {
    let y = scale_pow2(x, -k);
    y.is_finite() && scale_pow2(y, k) == x
}

fn scale_v(v: Vec3, k: i32) -> Vec3 {
    Vec3::new(scale_pow2(v.x, -k), scale_pow2(v.y, -k), scale_pow2(v.z, -k))
}

/// `scene` scaled by `2^-k` for the exponent of [`exponent_for`], and `k`; `None` with `k = 0`
/// when no scaling is needed, or when some coordinate would not scale exactly (a scene spanning
/// more than the `f32` exponent range: it is then traced as given).
pub fn scaled_scene(scene: &Scene) -> Result<(Option<Scene>, i32), Error> {
    let k = exponent_for(scene.bounds().max_abs());
    let lossless =
        k != 0 && scene.triangles().iter().all(|t| t.v.iter().all(|v| v.to_array().iter().all(|&x| exact(x, k))));
    if !lossless {
        return Ok((None, 0));
    }
    let tris: Vec<Triangle> = scene.triangles().iter().map(|t| Triangle { v: t.v.map(|v| scale_v(v, k)) }).collect();
    Ok((Some(Scene::new(tris)?), k))
}

/// `scene` and `bvh` scaled alike by [`scaled_scene`]'s power of two, and its exponent.
pub fn normalize(scene: &Scene, bvh: Bvh2) -> Result<(Option<Scene>, Bvh2, i32), Error> {
    let (scaled, k) = scaled_scene(scene)?;
    if scaled.is_none() {
        return Ok((None, bvh, 0));
    }
    let nodes: Vec<Bvh2Node> = bvh
        .nodes()
        .iter()
        .map(|n| Bvh2Node { bounds: Aabb::new(scale_v(n.bounds.min, k), scale_v(n.bounds.max, k)), kind: n.kind })
        .collect();
    let scaled_bvh = Bvh2::from_split_nodes(&nodes, 0, bvh.prim_order().to_vec(), bvh.prim_count())?;
    Ok((scaled, scaled_bvh, k))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponents_put_the_scale_in_half_to_one() {
        for s in [1e-40f32, 1e-30, 3e-6, 1e6, 1e14, 1e30, f32::MAX] {
            let k = exponent_for(s);
            let n = scale_pow2(s, -k);
            assert!((0.5..1.0).contains(&n), "{s}: k = {k}, {n}");
        }
        assert_eq!(exponent_for(1.0), 0);
        assert_eq!(exponent_for(60000.0), 0);
        assert_eq!(scale_pow2(1.0, 200), f32::INFINITY);
        assert_eq!(scale_pow2(f32::from_bits(1), 149), 1.0);
    }
}
