use crate::Ray;
use glam::{Vec3, Vec3A};

/// The far-distance padding `1 + 2 * gamma(3)` of Ize (2013), as in pbrt, with
/// `gamma(n) = n * eps / (1 - n * eps)` and `eps = 2^-24`, which makes the slab test conservative
/// for boxes in front of the origin.
pub const FAR_PAD: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// The per-ray constants of the slab test.
#[derive(Clone, Copy, Debug)]
pub struct SlabRay {
    /// Ray origin.
    pub origin: Vec3,
    /// Reciprocal direction; `1 / ±0` is `±inf`.
    pub inv_dir: Vec3,
    /// Per axis, whether the direction's sign bit is set (so `-0` counts as negative).
    pub negative: [bool; 3],
    /// Absolute slack of the entry/exit comparison (see [`SlabRay::hit`]); 0 unless set.
    pub slack: f32,
}

/// The entry and exit distances of a box that the ray hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxHit {
    /// Entry distance, clamped to the ray interval.
    pub t_enter: f32,
    /// Exit distance (padded), clamped to the ray interval.
    pub t_exit: f32,
}

impl SlabRay {
    /// Per-ray constants.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let d = ray.dir();
        Self {
            origin: ray.origin(),
            // One 4-wide division where SIMD is available; each lane is IEEE `1 / d`, as before.
            inv_dir: (Vec3A::ONE / Vec3A::from(d)).into(),
            negative: [d.x.is_sign_negative(), d.y.is_sign_negative(), d.z.is_sign_negative()],
            slack: 0.0,
        }
    }

    /// The robust slab test of box `[lo, hi]` over `[tmin, tmax]`.
    ///
    /// Near and far planes are picked by the direction's sign bit, so a `±0` component yields
    /// `±inf` distances rather than swapping planes. A `0 * inf` NaN (origin on a plane of a slab
    /// the ray runs parallel to) is ignored by `keep_max`/`keep_min`, which keep the
    /// accumulator when the candidate is NaN: the accumulators start from `tmin`/`tmax`, never NaN
    /// for a traceable ray, so a NaN never turns a hit into a miss.
    #[inline(always)]
    pub fn hit(&self, lo: Vec3, hi: Vec3, tmin: f32, tmax: f32) -> Option<BoxHit> {
        let (near, far) = self.planes(lo, hi);
        let tn = (near - self.origin) * self.inv_dir;
        let tf = (far - self.origin) * self.inv_dir * FAR_PAD;
        let t_enter = keep_max(keep_max(keep_max(tmin, tn.x), tn.y), tn.z);
        let t_exit = keep_min(keep_min(keep_min(tmax, tf.x), tf.y), tf.z);
        // The padding widens the interval only where `t > 0`; behind the origin (a negative
        // `tmin`) it narrows it, and a flat box there would be missed. The absolute slack, larger
        // than the padding for any box inside the scene, keeps the test conservative at the cost
        // of one addition. (Padding each distance by its sign instead halved traversal speed.)
        (t_enter <= t_exit + self.slack).then_some(BoxHit { t_enter, t_exit })
    }

    #[inline(always)]
    fn planes(&self, lo: Vec3, hi: Vec3) -> (Vec3, Vec3) {
        let pick = |neg: bool, l: f32, h: f32| if neg { (h, l) } else { (l, h) };
        let (nx, fx) = pick(self.negative[0], lo.x, hi.x);
        let (ny, fy) = pick(self.negative[1], lo.y, hi.y);
        let (nz, fz) = pick(self.negative[2], lo.z, hi.z);
        (Vec3::new(nx, ny, nz), Vec3::new(fx, fy, fz))
    }
}

/// `max(acc, x)`, keeping `acc` when `x` is NaN or equal. One `maxss` on x86 (`f32::max` needs
/// several instructions to treat NaN in either operand); a shader writes `select(acc, x, x > acc)`.
#[inline(always)]
pub fn keep_max(acc: f32, x: f32) -> f32 {
    if x > acc {
        x
    } else {
        acc
    }
}

/// `min(acc, x)`, keeping `acc` when `x` is NaN or equal; see [`keep_max`].
#[inline(always)]
pub fn keep_min(acc: f32, x: f32) -> f32 {
    if x < acc {
        x
    } else {
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f32; 3], d: [f32; 3]) -> SlabRay {
        SlabRay::new(&Ray { origin: o, tmin: 0.0, dir: d, tmax: f32::INFINITY })
    }

    #[test]
    fn axis_parallel_ray_on_a_box_plane_hits() {
        // Origin on the plane x = 0 of the box, direction along +y with x = +0 and -0.
        for dx in [0.0f32, -0.0] {
            let r = ray([0.0, -1.0, 0.5], [dx, 1.0, 0.0]);
            let h = r.hit(Vec3::ZERO, Vec3::ONE, 0.0, f32::INFINITY).expect("grazing ray must hit");
            assert!(h.t_enter <= 1.0 && h.t_exit >= 2.0);
        }
    }

    #[test]
    fn axis_parallel_ray_outside_misses() {
        assert!(ray([2.0, -1.0, 0.5], [0.0, 1.0, 0.0]).hit(Vec3::ZERO, Vec3::ONE, 0.0, f32::INFINITY).is_none());
        assert!(ray([-0.5, -1.0, 0.5], [-0.0, 1.0, 0.0]).hit(Vec3::ZERO, Vec3::ONE, 0.0, f32::INFINITY).is_none());
    }

    #[test]
    fn nan_candidates_are_ignored() {
        assert_eq!(keep_max(1.0, f32::NAN), 1.0);
        assert_eq!(keep_min(1.0, f32::NAN), 1.0);
        assert_eq!(keep_max(1.0, 2.0), 2.0);
        assert_eq!(keep_min(1.0, 0.5), 0.5);
    }

    #[test]
    fn interval_clamps() {
        let r = ray([-1.0, 0.5, 0.5], [1.0, 0.0, 0.0]);
        assert!(r.hit(Vec3::ZERO, Vec3::ONE, 0.0, 0.5).is_none());
        assert!(r.hit(Vec3::ZERO, Vec3::ONE, 2.5, 9.0).is_none());
        let h = r.hit(Vec3::ZERO, Vec3::ONE, 0.0, 9.0).unwrap();
        assert_eq!(h.t_enter, 1.0);
        assert!(h.t_exit >= 2.0 && h.t_exit < 2.0001);
    }

    #[test]
    fn flat_box_behind_the_origin_is_hit() {
        // A zero-thickness box at t = -1: the slack must cover the far padding's narrowing there.
        let mut r = ray([0.5, 0.5, 1.0], [0.0, 0.0, 1.0]);
        r.slack = 1e-5;
        let h = r.hit(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), f32::NEG_INFINITY, f32::INFINITY);
        let h = h.expect("flat box behind the origin must be hit");
        assert_eq!(h.t_enter, -1.0);
        // Without the slack the narrowed interval misses the box.
        r.slack = 0.0;
        assert!(r.hit(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), f32::NEG_INFINITY, f32::INFINITY).is_none());
    }

    #[test]
    fn flat_box_is_hit() {
        // Degenerate (zero-thickness) boxes, as for an axis-aligned triangle, must still be hit.
        let r = ray([0.5, 0.5, -1.0], [0.0, 0.0, 1.0]);
        assert!(r.hit(Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 1.0, 1.0), 0.0, f32::INFINITY).is_some());
    }
}
