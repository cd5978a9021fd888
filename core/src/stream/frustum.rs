//! Packet frustums (Garanzha & Loop 2010, Sec. 3.2, after Overbeck et al. 2008): a dominant axis
//! and two axis-aligned rectangles across it that bound every ray of the packet, plus the box of
//! the rays' segments, for packets whose rays share no dominant axis.

use crate::intersect::SlabRay;
use crate::traverse::begin_slab;
use crate::{Aabb, Ray};
use alloc::vec::Vec;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// [`Frustum::axis`] of a packet whose rays share no dominant axis: only the segments' box culls.
pub const NO_AXIS: u32 = 3;

/// The margin every bound is widened by, relative to the packet's reach (the scene's largest
/// coordinate magnitude plus the largest origin coordinate): 2^-14, some sixty times what the
/// slab test's rounding and the `f32` evaluation of the planes can move a bound by (each about
/// 2^-20 of the reach), so a box the slab test lets any ray of the packet enter is never culled.
pub const MARGIN: f32 = 1.0 / 16384.0;

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
    ///
    /// All in `f32`, one IEEE operation at a time in a fixed order (products rounded before they
    /// are added, correctly rounded divisions), so a GPU kernel that does the same gets the same
    /// bits. Each bound is then off by a few units of `2^-23` times the reach at most, far inside
    /// [`MARGIN`].
    pub fn build<'a>(rays: impl Iterator<Item = &'a Ray>, scene: &Aabb, scene_scale: f32) -> Frustum {
        let mut active = 0u32;
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let (mut mean, mut reach) = (Vec3::ZERO, 0.0f32);
        // Per axis: the smallest |d_a| / max|d| over the rays, and which signs d_a took.
        let mut min_share = [f32::INFINITY; 3];
        let (mut positive, mut negative) = ([false; 3], [false; 3]);
        let segments: Vec<Segment> = rays.filter_map(|ray| Segment::of(ray, scene, scene_scale)).collect();
        for s in &segments {
            active += 1;
            lo = lo.min(s.p0.min(s.p1));
            hi = hi.max(s.p0.max(s.p1));
            let dmax = s.d.abs().max_element();
            mean += s.d / dmax;
            reach = reach.max(s.reach);
            for a in 0..3 {
                min_share[a] = min_share[a].min(s.d[a].abs() / dmax);
                // A zero component counts as both signs: no frustum along that axis.
                positive[a] |= s.d[a] >= 0.0;
                negative[a] |= s.d[a] <= 0.0;
            }
        }
        if active == 0 {
            return Frustum::EMPTY;
        }
        // A power of two: the product is exact.
        let m = reach * MARGIN;
        let (lo, hi) = (lo - m, hi + m);
        let dir_signs = u32::from(mean.x < 0.0) | u32::from(mean.y < 0.0) << 1 | u32::from(mean.z < 0.0) << 2;
        let mut f =
            Frustum { lo: lo.to_array(), axis: NO_AXIS, hi: hi.to_array(), active, dir_signs, ..Frustum::EMPTY };
        if !(lo.is_finite() && hi.is_finite()) {
            // Segments beyond the f32 range: nothing is culled.
            (f.lo, f.hi) = ([f32::NEG_INFINITY; 3], [f32::INFINITY; 3]);
            return f;
        }
        // The dominant axis: one sign for every ray, and the largest smallest share (a later axis
        // wins a tie). Below a share of 1/4 the side planes would slope by more than 4 and their
        // f32 evaluation could stray toward the margin: such a packet keeps the box alone.
        let mut axis = None;
        for a in 0..3 {
            if positive[a] != negative[a] && axis.is_none_or(|b: usize| min_share[a] >= min_share[b]) {
                axis = Some(a);
            }
        }
        let Some(a) = axis.filter(|&a| min_share[a] >= 0.25) else { return f };
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        let (near, far) = (lo[a], hi[a]);
        let mut n = [f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY, f32::NEG_INFINITY];
        let mut fr = n;
        for s in &segments {
            for (x, rect) in [(near, &mut n), (far, &mut fr)] {
                let k = (x - s.p0[a]) / s.d[a];
                let (u, v) = (s.p0[b] + k * s.d[b], s.p0[c] + k * s.d[c]);
                *rect = [rect[0].min(u), rect[1].max(u), rect[2].min(v), rect[3].max(v)];
            }
        }
        f.axis = a as u32;
        (f.near, f.far) = (near, far);
        f.inv_span = if far > near { 1.0 / (far - near) } else { 0.0 };
        f.near_rect = [n[0] - m, n[1] + m, n[2] - m, n[3] + m];
        f.far_rect = [fr[0] - m, fr[1] + m, fr[2] - m, fr[3] + m];
        f
    }
}

/// An active ray's segment inside the scene box over its widened interval.
struct Segment {
    p0: Vec3,
    p1: Vec3,
    d: Vec3,
    /// The scene scale plus the origin's largest coordinate magnitude.
    reach: f32,
}

impl Segment {
    fn of(ray: &Ray, scene: &Aabb, scene_scale: f32) -> Option<Segment> {
        let slab: SlabRay = begin_slab(ray, scene_scale)?;
        let (t0, t1) = slab.widen(ray.tmin, ray.tmax);
        let h = slab.hit(scene.min, scene.max, t0, t1)?;
        let (o, d) = (ray.origin(), ray.dir());
        Some(Segment { p0: o + d * h.t_enter, p1: o + d * h.t_exit, d, reach: scene_scale + o.abs().max_element() })
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
