//! What every backend does to a batch before and after tracing it: rays in the prepared scene's
//! frame, far origins moved up to the scene, and rays no method can answer refused.
//!
//! Per ray, in this order:
//! 1. **Scale** origin and direction by the scene's power of two ([`super::normalize`]); `t` is
//!    unchanged. A ray that does not scale exactly (a component would overflow or lose bits to
//!    underflow) is refused.
//! 2. **Far origins.** The test subtracts the origin from each vertex in `f32`, so an origin far
//!    from the scene rounds every vertex by `ulp(|origin|)`: at `1e5` scene diameters that moves
//!    them by a hundredth of the scene, and methods that test boxes differently (kd against BVH2)
//!    found different triangles. An origin whose largest coordinate exceeds [`FAR_FACTOR`] times
//!    the scene's is moved along the ray to where it enters the scene box grown by an eighth of
//!    its size: the entry `t0` is rounded down to an `f32`, the new origin `o + t0 d` is computed
//!    in `f64` (the product is exact, the sum within `2^-53` of `|o|`) and rounded to `f32` (an
//!    error of an ulp of the scene's coordinates, as for an origin inside it). The interval
//!    becomes `[max(tmin - t0, 0), tmax - t0]`, and a hit's `t` comes back as `t0 + t` (rounded
//!    once from `f64`). A ray that misses the grown box over its interval is a miss without
//!    tracing; so is a far ray whose interval ends before the box.
//!    An origin beyond [`FAR_LIMIT`] times the scene's magnitude is refused.
//! 3. **Refusal.** A ray whose distances across the scene still come near the float range
//!    ([`crate::intersect::RayContext::is_reliable`]) is refused.
//!
//! A refused ray is traced as a non-traceable ray (no work) and answered with [`Hit::REFUSED`];
//! [`FramedRays::finish`] writes that and counts them for the [`crate::trace::Report`].

use super::PreparedScene;
use crate::intersect::{SlabRay, RELIABLE_LIMIT};
use crate::prepared::normalize::scale_pow2;
use crate::{Aabb, Hit, Ray};
use alloc::borrow::Cow;
use alloc::vec::Vec;

/// Origins whose largest coordinate magnitude exceeds this many times the scene's are moved up
/// to the scene (step 2 of the module docs).
pub const FAR_FACTOR: f32 = 4.0;

/// Origins whose largest coordinate magnitude exceeds this many times the scene's are refused:
/// beyond it the `f64` sum that moves them up rounds by more than an ulp of the scene.
pub const FAR_LIMIT: f32 = 4_294_967_296.0; // 2^32

/// What happened to one ray of a batch.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Fix {
    /// Traced as given (scaled alike in origin and direction: `t` unchanged).
    Keep,
    /// A hit's `t` comes back as `(t0 + t) * 2^exp`: the ray was moved up by `t0` and its
    /// direction scaled by `2^exp` more than its origin.
    Moved(f32, i32),
    /// A miss without tracing.
    Miss,
    /// Refused.
    Refused,
}

/// A batch in the prepared scene's frame ([`PreparedScene::frame_rays`]).
#[derive(Debug)]
pub struct FramedRays<'a> {
    rays: Cow<'a, [Ray]>,
    /// Per ray where any ray changed, else empty.
    fixes: Vec<Fix>,
}

/// What [`PreparedScene::check_rays`] finds in a chunk of rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RayCheck {
    /// Whether [`PreparedScene::frame_rays`] would change any of them.
    pub needs_framing: bool,
    /// How many are untraceable ([`Ray::is_traceable`] false).
    pub untraceable: usize,
}

/// A ray that every method answers as a miss without visiting a node.
const NOTHING: Ray = Ray { origin: [0.0; 3], tmin: 1.0, dir: [0.0, 0.0, 1.0], tmax: 0.0 };

impl FramedRays<'_> {
    /// The rays to trace.
    pub fn rays(&self) -> &[Ray] {
        &self.rays
    }

    /// Whether any ray was changed (scaled, moved, refused or answered without tracing): where
    /// none was, the rays are the caller's own and the hits need nothing.
    pub fn changed(&self) -> bool {
        !self.fixes.is_empty()
    }

    /// Puts the hits back in the caller's frame (moved rays' `t`, refused rays' [`Hit::REFUSED`])
    /// and returns how many rays were refused.
    pub fn finish(&self, hits: &mut [Hit]) -> usize {
        let mut refused = 0;
        for (i, hit) in hits.iter_mut().enumerate().take(self.fixes.len()) {
            refused += usize::from(self.finish_ray(i, hit));
        }
        refused
    }

    /// Puts one hit of ray `i` back in the caller's frame, as [`FramedRays::finish`] does for a
    /// batch's hits (a query that finds several hits per ray puts back each); returns whether
    /// the ray was refused (the hit is then [`Hit::REFUSED`]).
    #[inline]
    pub fn finish_ray(&self, i: usize, hit: &mut Hit) -> bool {
        match self.fixes.get(i).copied().unwrap_or(Fix::Keep) {
            Fix::Keep => {}
            Fix::Moved(t0, exp) => {
                if hit.is_hit() {
                    hit.t = scale_pow2((f64::from(t0) + f64::from(hit.t)) as f32, exp);
                }
            }
            Fix::Miss => *hit = Hit::MISS,
            Fix::Refused => {
                *hit = Hit::REFUSED;
                return true;
            }
        }
        false
    }
}

/// `x * 2^-k` where that is exact.
fn exact_scale(x: f32, k: i32) -> Option<f32> {
    let y = scale_pow2(x, -k);
    (y.is_finite() == x.is_finite() && scale_pow2(y, k) == x).then_some(y)
}

/// Bounds on a direction's largest component scaled alike with its origin (2^-64, 2^64): beyond
/// them it is scaled on its own ([`scaled`]).
const MODERATE_MIN: f32 = 1.0 / MODERATE_MAX;
const MODERATE_MAX: f32 = 18_446_744_073_709_551_616.0;

/// Whether a component of direction `d` is so small that its reciprocal overflows (`1 / d` is
/// infinite for `|d| < 1 / f32::MAX`, a subnormal): the slab test then puts a plane just off the
/// origin at `t = inf` where the exact crossing is finite, and culls a box the ray enters (a
/// fuzzed ray along `(5e-40, 8e-40, -0.25)` missed a triangle whose box began at `x = 2.7e-44`).
fn reciprocal_overflows(d: &[f32; 3]) -> bool {
    d.iter().any(|&x| x != 0.0 && (1.0 / x).is_infinite())
}

/// Whether the smallest nonzero component of direction `d` lies more than `2^126` below its
/// largest: the watertight test's shear (a component over the largest) is then subnormal or zero,
/// and the test traces another ray (a fuzzed ray along `(-0, 7e-45, 2.3e11)`, its shear `3e-56`
/// flushed to 0, hit a triangle at `t < 0` where the ray is outside the triangle's half-space).
/// Scaling by a power of two keeps the ratio, so no framing helps: such a ray is refused.
fn shear_not_normal(d: &[f32; 3]) -> bool {
    let largest = d.iter().fold(0.0f64, |m, &x| m.max(f64::from(x.abs())));
    d.iter().any(|&x| x != 0.0 && f64::from(x.abs()) < largest * SHEAR_MIN_RATIO)
}

/// `2^-126`: the smallest ratio of direction components whose shear is a normal `f32`.
const SHEAR_MIN_RATIO: f64 = 1.0 / 85_070_591_730_234_615_865_843_651_857_942_052_864.0;

/// Direction components at or above this (or zero) in a direction none of whose components exceeds
/// [`MODERATE_MAX`] lie at most `2^126` apart ([`shear_not_normal`]), and none is subnormal.
const PLAIN_MIN: f32 = 1.0 / 4_611_686_018_427_387_904.0;

/// `ray` scaled by `2^-k` and the exponent `e` a hit's `t` must be scaled back by, or `None`
/// where no exact scaling exists. Origin and direction scale alike where they can and the
/// direction stays moderate (`e = 0`); where it would overflow, underflow or leave
/// [`MODERATE_MIN`]..=[`MODERATE_MAX`] (unit directions into a scene of `1e-40` or `1e37`), it is
/// scaled to a largest component in `[0.5, 1)` instead, and the interval with it. In an unscaled
/// scene (`k = 0`) only a direction above [`MODERATE_MAX`] is scaled so: its distances are so
/// small that the triangle test's products of edge functions and depths underflow (a fuzzed
/// direction of `1.3e36` hit triangles behind its origin at `t = 0`). Directions below the range
/// stay as given there, and the reliability bound refuses those it must; but a direction of any
/// size with a component whose reciprocal overflows ([`reciprocal_overflows`]) is scaled as one
/// below the range would be in a scaled scene, and refused where that would take its largest past
/// [`MODERATE_MAX`] or its interval cannot follow exactly (so is one scaled with a scene): a fuzzed
/// ray along `(2.7e-43, -9.8e-25, -9.8e-25)`, its largest component below the range, kept its
/// infinite `1 / d_x` and missed a box whose x plane was `0`, just beside its origin. A direction
/// whose components lie more than `2^126` apart is refused first ([`shear_not_normal`]).
fn scaled(ray: &Ray, k: i32) -> Option<(Ray, i32)> {
    if shear_not_normal(&ray.dir) {
        return None;
    }
    let largest = ray.dir.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    if k == 0 && largest <= MODERATE_MAX && !reciprocal_overflows(&ray.dir) {
        return Some((*ray, 0));
    }
    let s = |v: [f32; 3], k: i32| -> Option<[f32; 3]> {
        Some([exact_scale(v[0], k)?, exact_scale(v[1], k)?, exact_scale(v[2], k)?])
    };
    let origin = s(ray.origin, k)?;
    // Alike only where the direction keeps a moderate size: scaled by 2^-125 with the origin (a
    // scene at 1e37), a unit direction made every ray fail the reliability bound (`reach^3 / |d|`)
    // and be refused, though its own scaling is exact.
    let moderate = |d: &[f32; 3]| {
        (MODERATE_MIN..=MODERATE_MAX).contains(&d[0].abs().max(d[1].abs()).max(d[2].abs())) && !reciprocal_overflows(d)
    };
    if let Some(dir) = s(ray.dir, k).filter(moderate) {
        return Some((Ray { origin, dir, ..*ray }, 0));
    }
    use crate::prepared::normalize::exponent_of;
    // The largest component to [0.5, 1), unless that leaves the smallest nonzero one subnormal:
    // then the smallest to [2^-126, 2^-125), if the largest stays moderate.
    let smallest = ray.dir.iter().map(|d| d.abs()).filter(|&d| d > 0.0).fold(f32::INFINITY, f32::min);
    let j = exponent_of(largest).min(exponent_of(smallest) + 125);
    let dir = s(ray.dir, j).filter(moderate)?;
    // t' = t * 2^(j - k): the interval scales by that, hits by its inverse.
    let e = k - j;
    Some((Ray { origin, dir, tmin: interval_scale(ray.tmin, e)?, tmax: interval_scale(ray.tmax, e)? }, e))
}

/// An interval end `x * 2^-e` where that is exact, or infinite where it overflows: every distance
/// the scaled ray can reach is a finite `f32`, so an end past the `f32` range bounds nothing more
/// than an infinite one (`tmax = 1e36` with a direction scaled down by `2^-121`).
fn interval_scale(x: f32, e: i32) -> Option<f32> {
    let y = scale_pow2(x, -e);
    if y.is_infinite() && x.is_finite() {
        return Some(y);
    }
    exact_scale(x, e)
}

/// The `t` interval of `ray` (in `f64`) inside `b`, clipped to the ray's own.
fn box_interval(ray: &Ray, b: &Aabb) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::from(ray.tmin), f64::from(ray.tmax));
    for i in 0..3 {
        let (o, d) = (f64::from(ray.origin[i]), f64::from(ray.dir[i]));
        let (bl, bh) = (f64::from(b.min[i]), f64::from(b.max[i]));
        if d == 0.0 {
            if o < bl || o > bh {
                return None;
            }
            continue;
        }
        let (a, c) = ((bl - o) / d, (bh - o) / d);
        lo = lo.max(a.min(c));
        hi = hi.min(a.max(c));
    }
    (lo <= hi).then_some((lo, hi))
}

/// Whether `ray` surely needs no change in an unscaled scene: every origin component within
/// `far`, some direction component above `min_dir` ([`min_reliable_dir`]), none above
/// [`MODERATE_MAX`] and none nonzero below [`PLAIN_MIN`] (none subnormal, none more than `2^126`
/// below another). Those bound the exact decision's `reach = scale + max|origin|` by
/// `scale + far` and its `max|d|` from below, so its slack is finite with room to spare. Only comparisons of single components, no horizontal
/// maximum and no product: a third of what the filter cost before, and it is run over every ray
/// of a batch (`docs/notes/*-benchmarks-embree-gap.md`, "A cheaper framing filter"). A NaN origin
/// component is never cleared; a NaN direction component may be, where another is large
/// (untraceable, such a ray is kept as given anyway).
#[inline(always)]
fn surely_kept(ray: &Ray, far: f32, min_dir: f32) -> bool {
    let near = |i: usize| ray.origin[i].abs() <= far;
    let sized = |i: usize| ray.dir[i].abs() > min_dir;
    let capped = |i: usize| ray.dir[i].abs() <= MODERATE_MAX;
    // Zero or at least 2^-62: a subnormal component may have a reciprocal that overflows, and
    // with the cap, components at most 2^126 apart keep the triangle test's shear normal.
    let plain = |i: usize| ray.dir[i].abs() >= PLAIN_MIN || ray.dir[i] == 0.0;
    near(0)
        & near(1)
        & near(2)
        & (sized(0) | sized(1) | sized(2))
        & (capped(0) & capped(1) & capped(2))
        & (plain(0) & plain(1) & plain(2))
}

/// Whether a ray that [`surely_kept`] clears is traceable ([`Ray::is_traceable`]): such a ray has
/// a finite origin and a non-zero direction already, so a finite direction and `tmin <= tmax` are
/// what is left. Comparisons only, no branch, for the clearing fold.
#[inline(always)]
fn plainly_traceable(ray: &Ray) -> bool {
    (ray.dir[0] * 0.0 + ray.dir[1] * 0.0 + ray.dir[2] * 0.0 == 0.0) & (ray.tmin <= ray.tmax)
}

/// The direction size above which a ray whose origin is within `far` of a scene of magnitude
/// `scale` surely has a finite slack: the slack is finite when `reach^2 * (reach / max|d|) <
/// RELIABLE_LIMIT` with `reach <= scale + far`, each step rounded in `f32`
/// ([`SlabRay::with_slack`]). Worked in `f64` and rounded up, with a margin of `2^-8` for the
/// half-dozen `f32` roundings of at most `2^-24` each; infinite (nothing cleared) where the bound
/// leaves the `f32` range.
fn min_reliable_dir(scale: f32, far: f32) -> f32 {
    let reach = f64::from(scale) + f64::from(far);
    let bound = reach * reach * reach * (1.0 + 1.0 / 256.0) / f64::from(RELIABLE_LIMIT);
    // The smallest `f32` not below the bound.
    -f32_down(-bound)
}

/// The largest `f32` not above `x` (for `x` within the `f32` range).
fn f32_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x {
        f32::from_bits(if y > 0.0 {
            y.to_bits() - 1
        } else if y == 0.0 {
            0x8000_0001
        } else {
            y.to_bits() + 1
        })
    } else {
        y
    }
}

/// The constants of one scene's framing decision.
struct Frame {
    /// The scene's largest coordinate magnitude (after its own scaling).
    scale: f32,
    /// The scene box grown by an eighth of its size: where far origins are moved to.
    grown: Aabb,
    /// Origins beyond this are far.
    far: f32,
    /// Directions with a component above this are surely reliable ([`min_reliable_dir`]).
    min_dir: f32,
    /// The scene's power-of-two exponent.
    k: i32,
}

impl Frame {
    /// What happens to `ray`, and the ray to trace.
    fn decide(&self, ray: &Ray) -> (Fix, Ray) {
        let Frame { scale, grown, far, k, .. } = *self;
        if !ray.is_traceable() {
            return (Fix::Keep, *ray);
        }
        let Some((r, exp)) = scaled(ray, k) else {
            return (Fix::Refused, NOTHING);
        };
        let reach = r.origin().abs().max_element();
        if reach > FAR_LIMIT * scale {
            return (Fix::Refused, NOTHING);
        }
        let (fix, r) = if reach > far {
            match box_interval(&r, &grown) {
                None => (Fix::Miss, NOTHING),
                Some((lo, _)) => {
                    let t0 = f32_down(lo).max(r.tmin);
                    let t0d = f64::from(t0);
                    let o = core::array::from_fn(|i| (f64::from(r.origin[i]) + t0d * f64::from(r.dir[i])) as f32);
                    let tmin = (f64::from(r.tmin) - t0d).max(0.0) as f32;
                    let tmax = (f64::from(r.tmax) - t0d) as f32;
                    (Fix::Moved(t0, exp), Ray { origin: o, tmin, dir: r.dir, tmax })
                }
            }
        } else if exp != 0 {
            (Fix::Moved(0.0, exp), r)
        } else {
            (Fix::Keep, r)
        };
        // A direction scaled up in an unscaled scene (`exp > 0`: hits come back multiplied by
        // `2^exp`) keeps the distances of the ray as given, so the bound applies to that ray too:
        // a direction of `2e-44` scaled to unit size traced reliably, and its hit at `t = 5.6e44`
        // came back infinite.
        let unreliable = |r: &Ray| !SlabRay::with_slack(r, scale).slack.is_finite();
        if fix != Fix::Miss && (unreliable(&r) || (k == 0 && exp > 0 && unreliable(ray))) {
            return (Fix::Refused, NOTHING);
        }
        (fix, r)
    }

    /// Whether `ray` is traced as given: first a filter of a few multiplies (the exact decision
    /// divides, and a serial pass of it cost a quarter of a fast method's trace), then the exact
    /// decision for the rays the filter does not clear.
    fn keeps(&self, ray: &Ray) -> bool {
        self.k == 0 && (surely_kept(ray, self.far, self.min_dir) || self.decide(ray) == (Fix::Keep, *ray))
    }
}

impl PreparedScene {
    fn frame(&self) -> Frame {
        let scale = self.scene_scale();
        let bounds = self.bvh.nodes()[0].bounds;
        let grow = (bounds.extent().max_element() / 8.0).max(scale * f32::EPSILON * 64.0);
        let grown = Aabb::new(bounds.min - grow, bounds.max + grow);
        let far = FAR_FACTOR * scale;
        Frame { scale, grown, far, min_dir: min_reliable_dir(scale, far), k: self.exponent }
    }

    /// Whether [`PreparedScene::frame_rays`] would change any ray of `rays`. A backend may ask
    /// this of a batch's chunks in parallel and, where none needs a change, trace the batch as
    /// given (the usual case: no copy, no refusals).
    pub fn needs_framing(&self, rays: &[Ray]) -> bool {
        let frame = self.frame();
        // Without a branch per ray (the compiler vectorizes it), then exactly where that fails.
        let cleared = frame.k == 0 && rays.iter().fold(true, |all, r| all & surely_kept(r, frame.far, frame.min_dir));
        !cleared && !rays.iter().all(|r| frame.keeps(r))
    }

    /// One pass over `rays` that says what [`PreparedScene::needs_framing`] says and counts the
    /// untraceable rays ([`Ray::untraceable_flag`]) in the same loop, for a backend that checks
    /// each chunk before tracing it: the count rides on the loads the check makes anyway.
    pub fn check_rays(&self, rays: &[Ray]) -> RayCheck {
        let frame = self.frame();
        // The usual chunk: every ray surely kept and plainly traceable, decided by one fold without
        // a branch per ray, as in `needs_framing`: nothing to frame, nothing untraceable. Anything
        // else is decided exactly, ray by ray.
        let clean = frame.k == 0
            && rays.iter().fold(true, |all, r| all & surely_kept(r, frame.far, frame.min_dir) & plainly_traceable(r));
        if clean {
            return RayCheck { needs_framing: false, untraceable: 0 };
        }
        RayCheck { needs_framing: self.needs_framing(rays), untraceable: crate::trace::count_untraceable(rays) }
    }

    /// The batch `rays` in this scene's frame (see the module docs); borrows the rays where none
    /// needs a change.
    pub fn frame_rays<'a>(&self, rays: &'a [Ray]) -> FramedRays<'a> {
        if !self.needs_framing(rays) {
            return FramedRays { rays: Cow::Borrowed(rays), fixes: Vec::new() };
        }
        let frame = self.frame();
        let (fixes, out): (Vec<Fix>, Vec<Ray>) = rays.iter().map(|r| frame.decide(r)).unzip();
        FramedRays { rays: Cow::Owned(out), fixes }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The filter clears only rays the exact decision keeps in an unscaled scene (origin within
    /// the far threshold, finite slack, direction not above the moderate range): rays from all
    /// over the float range.
    #[test]
    fn the_filter_clears_only_rays_the_exact_decision_keeps() {
        let scale = 3.0f32;
        let far = FAR_FACTOR * scale;
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let (mut cleared, mut checked) = (0, 0);
        for _ in 0..200_000 {
            // Magnitudes 2^-120 .. 2^120, both signs, any mix per component.
            let mut v = || {
                let bits = next();
                let mag = 2f32.powi((bits % 241) as i32 - 120) * (1.0 + (bits >> 32) as f32 / 4.3e9);
                if bits & (1 << 20) != 0 {
                    -mag
                } else {
                    mag
                }
            };
            let ray = Ray { origin: [v(), v(), v()], tmin: 0.0, dir: [v(), v(), v()], tmax: f32::INFINITY };
            if !ray.is_traceable() {
                continue;
            }
            checked += 1;
            if surely_kept(&ray, far, min_reliable_dir(scale, far)) {
                cleared += 1;
                let reach = ray.origin.iter().fold(0.0f32, |m, x| m.max(x.abs()));
                assert!(reach <= far, "cleared a far ray: {ray:?}");
                assert!(SlabRay::with_slack(&ray, scale).slack.is_finite(), "cleared an unreliable ray: {ray:?}");
                assert!(ray.dir.iter().all(|d| d.abs() <= MODERATE_MAX), "cleared a huge direction: {ray:?}");
                assert!(!reciprocal_overflows(&ray.dir), "cleared a direction whose reciprocal overflows: {ray:?}");
                assert!(!shear_not_normal(&ray.dir), "cleared a direction whose shear is not normal: {ray:?}");
            }
        }
        // Components drawn from 2^-120 to 2^120: about 2% have all three at 2^-62 or above (or
        // zero) and at most 2^64, what the filter clears.
        assert!(cleared > checked / 100 && cleared < checked, "{cleared} of {checked} cleared");
    }

    /// A camera ray into a scene at 1e37 (scaled by 2^-125): its unit direction scales exactly
    /// with the origin, but so small that the ray failed the reliability bound and was refused.
    /// Scaled on its own, it stays reliable, and a hit's `t` is scaled back by 2^125.
    #[test]
    fn unit_directions_into_huge_scenes_stay_reliable() {
        let ray = Ray {
            origin: [4.756_067e37, 5.105_386e37, 8.271_189e37],
            tmin: 0.0,
            dir: [-0.680_795_9, 0.022_825_062, -0.732_117_5],
            tmax: f32::INFINITY,
        };
        let (r, e) = scaled(&ray, 125).expect("scales exactly");
        assert_eq!(e, 125);
        assert_eq!(r.dir, ray.dir, "a unit direction keeps its size");
        assert!(SlabRay::with_slack(&r, 0.8).slack.is_finite());
    }

    /// A fuzzed ray into an unscaled scene of size 12, its direction `1.3e36` along z: its
    /// distances of order `1e-37` made the triangle test's products underflow, and triangles
    /// behind the origin were hit at `t = 0`. Its direction is now scaled to unit size, the
    /// interval with it, and the `tmax` of `1.3e36`, past the `f32` range once scaled, bounds
    /// nothing: it becomes infinite.
    #[test]
    fn huge_directions_are_scaled_to_unit_size_in_unscaled_scenes() {
        let ray = Ray { origin: [0.0, 0.0, 1.0], tmin: 0.0, dir: [0.0, 0.0, 1.305_771e36], tmax: 1.305_771e36 };
        assert!(!surely_kept(&ray, 48.0, min_reliable_dir(12.0, 48.0)), "the filter clears it");
        let (r, e) = scaled(&ray, 0).expect("scales exactly");
        assert_eq!((e, r.origin), (-120, ray.origin));
        assert!((0.5..1.0).contains(&r.dir[2]), "{r:?}");
        assert_eq!((r.tmin, r.tmax), (0.0, f32::INFINITY));
        // Directions of ordinary sizes are left as they are.
        let unit = Ray { dir: [0.0, 0.6, 0.8], tmax: 5.0, ..ray };
        assert_eq!(scaled(&unit, 0), Some((unit, 0)));
    }

    /// A fuzzed ray along `(5.05e-40, 8.27e-40, -0.25)`: `1 / 5.05e-40` overflows, and the slab
    /// test culled a box whose x plane lay at `2.7e-44`, just off the origin, that the ray enters at
    /// `t = 5.3e-5`. Its components lie more than `2^126` apart, so its shear is subnormal: it is
    /// refused, as is the ray along `(-0, 7e-45, 2.3e11)` whose shear flushed to 0. A direction
    /// with such components nearer its largest is scaled until they are normal, with its interval,
    /// or refused where the interval cannot follow exactly.
    #[test]
    fn subnormal_direction_components_are_scaled_to_normal_or_refused() {
        let ray = Ray { origin: [0.0; 3], tmin: 0.0, dir: [5.050_95e-40, 8.265_2e-40, -0.25], tmax: 137_439_990_000.0 };
        assert!(reciprocal_overflows(&ray.dir) && shear_not_normal(&ray.dir));
        assert!(!surely_kept(&ray, 48.0, min_reliable_dir(12.0, 48.0)), "the filter clears it");
        assert_eq!(scaled(&ray, 0), None);
        let flushed = Ray { tmin: -0.5, dir: [-0.0, 7e-45, 225_830_750_000.0], tmax: 225_831_060_000.0, ..ray };
        assert!(!surely_kept(&flushed, 48.0, min_reliable_dir(12.0, 48.0)) && scaled(&flushed, 0).is_none());
        // Components of 1e-19 and 1, all normal: the filter sends them to the decision, which
        // keeps them (2^63 apart at most).
        let slight = Ray { dir: [1e-19, 0.0, 1.0], ..ray };
        assert!(!surely_kept(&slight, 48.0, min_reliable_dir(12.0, 48.0)));
        assert_eq!(scaled(&slight, 0), Some((slight, 0)));
        let near_axis = Ray { dir: [5.050_95e-40, 8.265_2e-40, -2.5e-10], ..ray };
        assert!(reciprocal_overflows(&near_axis.dir) && !shear_not_normal(&near_axis.dir));
        let (r, e) = scaled(&near_axis, 0).expect("scales exactly");
        let factor = r.dir[2] / near_axis.dir[2];
        assert_eq!(r.dir, near_axis.dir.map(|d| d * factor), "scaled by one power of two");
        assert!(r.dir.iter().all(|d| d.abs() >= f32::MIN_POSITIVE) && !reciprocal_overflows(&r.dir));
        assert_eq!((r.origin, r.tmin, r.tmax, factor), (ray.origin, 0.0, ray.tmax / factor, 2f32.powi(e)));
        // An interval end that loses bits when scaled (the smallest subnormal): refused.
        let inexact = Ray { tmin: f32::from_bits(1), ..near_axis };
        assert_eq!(scaled(&inexact, 0), None);
        // A direction below the moderate range with a subnormal component (a fuzzed ray that
        // missed a box whose x plane lay at 0, beside its origin at x = -2.9e-41): scaled so
        // that the largest is in [0.5, 1) and every component normal.
        let tiny =
            Ray { origin: [-2.8699e-41, -2.68e-43, -0.5], dir: [2.68e-43, -9.758_146e-25, -9.796_413e-25], ..ray };
        assert!(reciprocal_overflows(&tiny.dir) && !shear_not_normal(&tiny.dir));
        let (r, e) = scaled(&tiny, 0).expect("scales exactly");
        assert!((0.5..1.0).contains(&r.dir[2].abs()) && !reciprocal_overflows(&r.dir), "{r:?}");
        assert_eq!((r.origin, r.tmax * 2f32.powi(e)), (tiny.origin, tiny.tmax));
        // Scaled up, a direction keeps the distances of the ray as given, so the reliability bound
        // judges that ray: one of nothing but subnormals (the instanced check's adversarial ray,
        // whose hit lies at `t = 5.6e44`, past the `f32` range) is refused, where the fuzzed
        // ray, reliable as given, is traced scaled.
        let frame = Frame {
            scale: 30.0,
            grown: Aabb::new(glam::Vec3::splat(-34.0), glam::Vec3::splat(34.0)),
            far: 120.0,
            min_dir: min_reliable_dir(30.0, 120.0),
            k: 0,
        };
        let subnormal = Ray { origin: [15.629_128, 25.815_441, -9.516_532], dir: [-2.1e-44, -3.8e-44, 1.7e-44], ..ray };
        assert_eq!(frame.decide(&subnormal).0, Fix::Refused);
        assert!(matches!(frame.decide(&tiny).0, Fix::Moved(t0, e) if t0 == 0.0 && e > 0), "{:?}", frame.decide(&tiny));
        // Components more than 2^190 apart cannot all be normal with the largest moderate.
        let apart = Ray { dir: [1e-44, 0.0, 1e19], ..ray };
        assert_eq!(scaled(&apart, 0), None);
    }
}
