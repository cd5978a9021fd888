//! Packet frustums (Garanzha & Loop 2010, Sec. 3.2, after Overbeck et al. 2008): a dominant axis
//! and two axis-aligned rectangles across it that bound every ray of the packet, plus the box of
//! the rays' segments, for packets whose rays share no dominant axis.

use crate::intersect::SlabRay;
use crate::traverse::begin_slab;
use crate::{Aabb, Ray};
use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3};

/// [`Frustum::axis`] of a packet whose rays share no dominant axis: only the segments' box culls.
pub const NO_AXIS: u32 = 3;

/// The margin every bound is widened by, relative to the packet's reach (the scene's largest
/// coordinate magnitude plus the largest origin coordinate): 2^-14, some sixty times what the
/// slab test's rounding and the `f32` evaluation of the planes can move a bound by (each about
/// 2^-20 of the reach), so a box the slab test lets any ray of the packet enter is never culled.
pub const MARGIN: f64 = 1.0 / 16384.0;

/// A packet's frustum, laid out for the GPU as well (`repr(C)`, 80 bytes, twenty 4-byte words).
///
/// Along the dominant axis `a` (and its two others `b = a + 1`, `c = a + 2`, mod 3), the frustum
/// spans `[near, far]`; at `near` its cross-section is `near_rect` = (b low, b high, c low, c high),
/// at `far` it is `far_rect`, and in between the bounds are linear. Every ray's segment inside the
/// scene box, widened by the slack the traversals test boxes with, lies inside (up to
/// [`MARGIN`], added to every bound). `lo`/`hi` bound the same segments as a box.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct Frustum {
    /// Lower corner of the segments' box.
    pub lo: [f32; 3],
    /// The dominant axis, or [`NO_AXIS`].
    pub axis: u32,
    /// Upper corner of the segments' box.
    pub hi: [f32; 3],
    /// Rays of the packet that can hit anything (0: the frustum culls every box).
    pub active: u32,
    /// Start of the span along the dominant axis.
    pub near: f32,
    /// End of the span.
    pub far: f32,
    /// `1 / (far - near)`, or 0 for a span of one plane.
    pub inv_span: f32,
    /// Sign bits of the packet's mean direction (bit `i`: axis `i` negative), which order a
    /// node's children along the frustum.
    pub dir_signs: u32,
    /// Cross-section at `near`: `b` low, `b` high, `c` low, `c` high.
    pub near_rect: [f32; 4],
    /// Cross-section at `far`.
    pub far_rect: [f32; 4],
}

/// How a frustum tests a box: the exact-rule [`FrustumCull`], or a deliberately broken rule in
/// the conformance suite's fault injection.
pub trait FrustumTest {
    /// Whether a box may hold something a ray of the frustum's packet reaches.
    fn overlaps(f: &Frustum, lo: Vec3, hi: Vec3) -> bool;
}

/// The frustum test of the method: the segments' box, the span along the dominant axis, then the
/// four side planes, each evaluated at both ends of the box's overlap with the span (a plane's
/// bound is linear along the axis, so its extreme over the overlap is at an end).
#[derive(Clone, Copy, Debug, Default)]
pub struct FrustumCull;

impl FrustumTest for FrustumCull {
    #[inline(always)]
    fn overlaps(f: &Frustum, lo: Vec3, hi: Vec3) -> bool {
        if f.active == 0 {
            return false;
        }
        for i in 0..3 {
            if hi[i] < f.lo[i] || lo[i] > f.hi[i] {
                return false;
            }
        }
        if f.axis == NO_AXIS {
            return true;
        }
        let a = f.axis as usize;
        let (x0, x1) = (lo[a].max(f.near), hi[a].min(f.far));
        if x0 > x1 {
            return false;
        }
        let (s0, s1) = ((x0 - f.near) * f.inv_span, (x1 - f.near) * f.inv_span);
        let at = |k: usize, s: f32| f.near_rect[k] + (f.far_rect[k] - f.near_rect[k]) * s;
        for (side, axis) in [(0, (a + 1) % 3), (2, (a + 2) % 3)] {
            // Below the lower plane at both ends, or above the upper plane at both ends.
            if hi[axis] < at(side, s0).min(at(side, s1)) || lo[axis] > at(side + 1, s0).max(at(side + 1, s1)) {
                return false;
            }
        }
        true
    }
}

impl Frustum {
    /// A frustum that culls everything (a packet none of whose rays can hit anything).
    pub const EMPTY: Frustum = Frustum {
        lo: [0.0; 3],
        axis: NO_AXIS,
        hi: [0.0; 3],
        active: 0,
        near: 0.0,
        far: 0.0,
        inv_span: 0.0,
        dir_signs: 0,
        near_rect: [0.0; 4],
        far_rect: [0.0; 4],
    };

    /// The frustum of `rays` in a scene with bounds `scene` and largest coordinate magnitude
    /// `scene_scale`. A ray that cannot be traced, or whose slab test misses the scene box over
    /// its widened interval, is left out: no method finds a hit for it.
    pub fn build<'a>(rays: impl Iterator<Item = &'a Ray> + Clone, scene: &Aabb, scene_scale: f32) -> Frustum {
        // Each active ray's segment inside the scene box, in f64.
        let segment = |ray: &Ray| -> Option<(DVec3, DVec3, DVec3, f64)> {
            let slab: SlabRay = begin_slab(ray, scene_scale)?;
            let (t0, t1) = slab.widen(ray.tmin, ray.tmax);
            let h = slab.hit(scene.min, scene.max, t0, t1)?;
            let (o, d) = (ray.origin().as_dvec3(), ray.dir().as_dvec3());
            let reach = f64::from(scene_scale) + o.abs().max_element();
            Some((o + d * f64::from(h.t_enter), o + d * f64::from(h.t_exit), d, reach))
        };
        let mut active = 0u32;
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let (mut mean, mut reach) = (DVec3::ZERO, 0.0f64);
        // Per axis: the smallest |d_a| / max|d| over the rays, and whether every d_a had one sign.
        let mut min_share = [f64::INFINITY; 3];
        let mut signs = [(false, false); 3];
        for ray in rays.clone() {
            let Some((p0, p1, d, r)) = segment(ray) else { continue };
            active += 1;
            lo = lo.min(p0.min(p1));
            hi = hi.max(p0.max(p1));
            let dmax = d.abs().max_element();
            mean += d / dmax;
            reach = reach.max(r);
            for a in 0..3 {
                min_share[a] = min_share[a].min(d[a].abs() / dmax);
                if d[a] > 0.0 {
                    signs[a].0 = true;
                } else if d[a] < 0.0 {
                    signs[a].1 = true;
                } else {
                    (signs[a].0, signs[a].1) = (true, true);
                }
            }
        }
        if active == 0 {
            return Frustum::EMPTY;
        }
        let m = reach * MARGIN;
        let (lo, hi) = (lo - m, hi + m);
        let dir_signs = (0..3).map(|a| u32::from(mean[a] < 0.0) << a).sum();
        // Rounding to f32 moves a bound by far less than the margin.
        let mut f = Frustum {
            lo: lo.as_vec3().to_array(),
            axis: NO_AXIS,
            hi: hi.as_vec3().to_array(),
            active,
            dir_signs,
            ..Frustum::EMPTY
        };
        if !(lo.is_finite() && hi.is_finite()) {
            // Segments beyond the f32 range: the box alone, unbounded.
            (f.lo, f.hi) = ([f32::NEG_INFINITY; 3], [f32::INFINITY; 3]);
            return f;
        }
        // The dominant axis: one sign for every ray, and the largest smallest share. Below a
        // share of 1/4 the side planes would slope by more than 4 and the f32 evaluation of them
        // could stray past the margin: such a packet keeps the box alone.
        let Some(a) = (0..3).filter(|&a| signs[a].0 != signs[a].1).max_by(|&x, &y| min_share[x].total_cmp(&min_share[y]))
        else {
            return f;
        };
        if min_share[a] < 0.25 {
            return f;
        }
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        let (near, far) = (lo[a], hi[a]);
        let (mut n, mut fr) = ([f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY], [0.0; 4]);
        fr.copy_from_slice(&n);
        for ray in rays {
            let Some((p0, _, d, _)) = segment(ray) else { continue };
            for (x, rect) in [(near, &mut n), (far, &mut fr)] {
                let s = (x - p0[a]) / d[a];
                let (u, v) = (p0[b] + s * d[b], p0[c] + s * d[c]);
                *rect = [rect[0].min(u), rect[1].max(u), rect[2].min(v), rect[3].max(v)];
            }
        }
        let widen = |r: [f64; 4]| [r[0] - m, r[1] + m, r[2] - m, r[3] + m];
        let (n, fr) = (widen(n), widen(fr));
        f.axis = a as u32;
        f.near = near as f32;
        f.far = far as f32;
        f.inv_span = if f.far > f.near { 1.0 / (f.far - f.near) } else { 0.0 };
        f.near_rect = [n[0] as f32, n[1] as f32, n[2] as f32, n[3] as f32];
        f.far_rect = [fr[0] as f32, fr[1] as f32, fr[2] as f32, fr[3] as f32];
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intersect::test_values::Rng;

    fn unit(rng: &mut Rng) -> f32 {
        (rng.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Packets of nearby rays (shared origin region, spread directions, sometimes mixed signs)
    /// against many small boxes: every box the slab test lets a ray of the packet enter over its
    /// widened interval must overlap the frustum.
    #[test]
    fn no_box_a_ray_enters_is_culled() {
        let mut rng = Rng(7);
        let scene = Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0));
        let scale = scene.max_abs();
        let (mut culled, mut tested) = (0, 0);
        for packet in 0..300 {
            let spread = [0.01, 0.2, 2.0][packet % 3];
            let o0 = Vec3::new(unit(&mut rng), unit(&mut rng), unit(&mut rng)) * 30.0 - 15.0;
            let d0 = Vec3::new(unit(&mut rng), unit(&mut rng), unit(&mut rng)) * 2.0 - 1.0;
            let rays: alloc::vec::Vec<Ray> = (0..32)
                .map(|_| {
                    let jitter = Vec3::new(unit(&mut rng), unit(&mut rng), unit(&mut rng)) - 0.5;
                    let o = o0 + jitter * spread * 3.0;
                    let d = d0 + (Vec3::new(unit(&mut rng), unit(&mut rng), unit(&mut rng)) - 0.5) * spread;
                    Ray::new(o, d, 0.0, if packet % 2 == 0 { f32::INFINITY } else { 8.0 })
                })
                .collect();
            let f = Frustum::build(rays.iter(), &scene, scale);
            for _ in 0..200 {
                let c = Vec3::new(unit(&mut rng), unit(&mut rng), unit(&mut rng)) * 20.0 - 10.0;
                let h = Vec3::new(unit(&mut rng), unit(&mut rng), unit(&mut rng)) * 0.5;
                let (lo, hi) = (c - h, c + h);
                let entered = rays.iter().any(|r| {
                    let Some(slab) = begin_slab(r, scale) else { return false };
                    let (t0, t1) = slab.widen(r.tmin, r.tmax);
                    slab.hit(lo, hi, t0, t1).is_some()
                });
                let overlaps = FrustumCull::overlaps(&f, lo, hi);
                assert!(!entered || overlaps, "packet {packet}: a box a ray enters was culled: {lo} {hi} {f:?}");
                tested += 1;
                culled += usize::from(!overlaps);
            }
        }
        // The test means something only if the frustums do cull.
        assert!(culled > tested / 2, "only {culled} of {tested} boxes culled");
    }

    #[test]
    fn untraceable_and_missing_rays_leave_an_empty_frustum() {
        let scene = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let rays = [Ray::new(Vec3::NAN, Vec3::X, 0.0, 1.0), Ray::new(Vec3::splat(5.0), Vec3::X, 0.0, 1.0)];
        let f = Frustum::build(rays.iter(), &scene, 1.0);
        assert_eq!(f.active, 0);
        assert!(!FrustumCull::overlaps(&f, Vec3::ZERO, Vec3::ONE));
    }
}
