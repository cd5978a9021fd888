//! Primary rays: a pinhole camera, pixels enumerated in Morton (Z-) order as in the papers, so
//! consecutive rays are coherent and a batch covers a compact tile of the screen.

use glam::Vec3;
use raytrail_core::scene::Scene;
use raytrail_core::{Aabb, Ray};

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Center of projection.
    pub eye: Vec3,
    /// Point seen at the center of the image.
    pub target: Vec3,
    /// Approximate up direction (need not be perpendicular to the view direction).
    pub up: Vec3,
    /// Tangent of half the vertical field of view: half the image height at unit distance.
    /// Given as a tangent, not an angle, so that no platform-dependent `tan` enters the rays.
    pub tan_half_vfov: f32,
}

impl Camera {
    /// `tan(22.5 degrees) = sqrt(2) - 1`: the [`Camera::tan_half_vfov`] of a 45-degree field of
    /// view.
    pub const TAN_HALF_45_DEG: f32 = core::f32::consts::SQRT_2 - 1.0;

    /// Direction from the scene's center towards the eye of [`Camera::framing`]: oblique to every
    /// axis, so axis-aligned planes are seen neither edge-on nor face-on.
    pub const VIEW_FROM: Vec3 = Vec3::new(0.45, 0.35, 0.82);

    /// A generic view of the whole box: looking at its center from direction [`Self::VIEW_FROM`],
    /// 45-degree vertical field of view, from just far enough that all eight corners are in view
    /// (for images at least as wide as tall), so the scene fills the image. The eye is outside the
    /// box.
    pub fn framing(bounds: Aabb) -> Camera {
        let center = bounds.center();
        let tan_half = Self::TAN_HALF_45_DEG;
        let mut cam = Camera { eye: center, target: center, up: Vec3::Y, tan_half_vfov: tan_half };
        let back = Self::VIEW_FROM.normalize();
        let (right, up) = cam.basis(-back);
        // The eye at `center + back * d` sees corner offset `o` at depth `d - o.back`; it is in
        // view when its lateral offsets are within `tan_half` of that depth.
        let mut distance: f32 = 0.0;
        for k in 0..8 {
            let corner = Vec3::new(
                if k & 1 == 0 { bounds.min.x } else { bounds.max.x },
                if k & 2 == 0 { bounds.min.y } else { bounds.max.y },
                if k & 4 == 0 { bounds.min.z } else { bounds.max.z },
            );
            let o = corner - center;
            distance = distance.max(o.dot(back) + o.dot(right).abs().max(o.dot(up).abs()) / tan_half);
        }
        // Degenerate (point) scenes still need the eye some distance away.
        let distance = if distance > 0.0 { 1.02 * distance } else { 1.0 };
        cam.eye = center + back * distance;
        cam
    }

    /// Right and true up vectors for a view along `forward` (unit).
    fn basis(&self, forward: Vec3) -> (Vec3, Vec3) {
        let up_hint = if forward.cross(self.up).length_squared() > 1e-6 { self.up } else { Vec3::Z };
        let right = forward.cross(up_hint).normalize();
        (right, right.cross(forward))
    }

    /// The ray through the point `(px, py)` of a `width` x `height` image (pixel units, y down;
    /// pixel centers at half-integers): unit direction, `t` in `[0, inf]`.
    pub fn ray(&self, px: f32, py: f32, width: u32, height: u32) -> Ray {
        let forward = unit(self.target - self.eye);
        let (right, up) = self.basis(forward);
        let half_h = self.tan_half_vfov;
        let half_w = half_h * width as f32 / height as f32;
        let sx = (2.0 * px / width as f32 - 1.0) * half_w;
        let sy = (1.0 - 2.0 * py / height as f32) * half_h;
        Ray::new(self.eye, unit(forward + right * sx + up * sy), 0.0, f32::INFINITY)
    }
}

/// `v` scaled to unit length at any magnitude. Where `|v|^2` is a normal float this is glam's
/// `normalize` (so ordinary scenes keep their rays bit for bit); where it underflows or overflows
/// (a scene at 1e-40 or 1e37), `v` is first divided by its largest component, which squares
/// safely: plain `normalize` gave NaN directions there.
fn unit(v: Vec3) -> Vec3 {
    if v.length_squared().is_normal() {
        return v.normalize();
    }
    let m = v.abs().max_element();
    if m > 0.0 && m.is_finite() {
        (v / m).normalize()
    } else {
        v.normalize()
    }
}

/// The Morton code of pixel `(x, y)`: bits of x in the even positions, bits of y in the odd ones.
pub fn morton_encode(x: u32, y: u32) -> u64 {
    spread_bits(x) | (spread_bits(y) << 1)
}

/// Inserts a zero bit above each bit of `v`.
fn spread_bits(v: u32) -> u64 {
    let mut v = u64::from(v);
    v = (v | (v << 16)) & 0x0000_FFFF_0000_FFFF;
    v = (v | (v << 8)) & 0x00FF_00FF_00FF_00FF;
    v = (v | (v << 4)) & 0x0F0F_0F0F_0F0F_0F0F;
    v = (v | (v << 2)) & 0x3333_3333_3333_3333;
    (v | (v << 1)) & 0x5555_5555_5555_5555
}

/// All pixels of a `width` x `height` image in increasing Morton code; any size, not only powers
/// of two (pixels of the enclosing power-of-two square that fall outside are skipped).
pub fn morton_order(width: u32, height: u32) -> Vec<(u32, u32)> {
    let mut pixels: Vec<(u32, u32)> = (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).collect();
    pixels.sort_unstable_by_key(|&(x, y)| morton_encode(x, y));
    pixels
}

/// Primary rays of `camera` through the centers of a `width` x `height` image, in Morton order.
pub fn primary_from(camera: &Camera, width: u32, height: u32) -> Vec<Ray> {
    morton_order(width, height)
        .into_iter()
        .map(|(x, y)| camera.ray(x as f32 + 0.5, y as f32 + 0.5, width, height))
        .collect()
}

/// Primary rays of [`Camera::framing`] of the scene's bounds, `width` x `height`, in Morton order.
pub fn primary(scene: &Scene, width: u32, height: u32) -> Vec<Ray> {
    primary_from(&Camera::framing(scene.bounds()), width, height)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Directions are unit vectors at every scene scale (they were NaN at 1e-40 and 1e37), and
    /// about the same as at scale 1.
    #[test]
    fn primary_rays_have_unit_directions_at_any_scale() {
        let at = |s: f32| {
            let b = Aabb::new(Vec3::new(-1.0, -2.0, -3.0) * s, Vec3::new(3.0, 2.0, 1.0) * s);
            primary_from(&Camera::framing(b), 8, 6)
        };
        let unit = at(1.0);
        for s in [1e-40f32, 1e-30, 1e30, 1e37] {
            for (r, u) in at(s).iter().zip(&unit) {
                let d = Vec3::from_array(r.dir);
                assert!(d.is_finite() && (d.length() - 1.0).abs() < 1e-5, "scale {s}: {r:?}");
                assert!(d.distance(Vec3::from_array(u.dir)) < 1e-3, "scale {s}: {d} against {:?}", u.dir);
            }
        }
    }

    #[test]
    fn morton_order_of_4x4() {
        let expected = [
            (0, 0),
            (1, 0),
            (0, 1),
            (1, 1),
            (2, 0),
            (3, 0),
            (2, 1),
            (3, 1),
            (0, 2),
            (1, 2),
            (0, 3),
            (1, 3),
            (2, 2),
            (3, 2),
            (2, 3),
            (3, 3),
        ];
        assert_eq!(morton_order(4, 4), expected);
    }

    #[test]
    fn morton_order_of_non_square_covers_every_pixel_once() {
        let order = morton_order(5, 3);
        assert_eq!(order.len(), 15);
        assert_eq!(&order[..6], &[(0, 0), (1, 0), (0, 1), (1, 1), (2, 0), (3, 0)]);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 15);
        assert_eq!(morton_encode(0xFFFF_FFFF, 0), 0x5555_5555_5555_5555);
        assert_eq!(morton_encode(0, 1), 2);
    }

    #[test]
    fn camera_sees_the_center() {
        let b = Aabb::new(Vec3::new(-1.0, 2.0, 3.0), Vec3::new(1.0, 4.0, 7.0));
        let cam = Camera::framing(b);
        let r = cam.ray(50.0, 50.0, 100, 100);
        let to_center = (b.center() - cam.eye).normalize();
        assert!(r.dir().dot(to_center) > 0.99999);
        // The eye is outside the box.
        let e = cam.eye;
        assert!(e.cmplt(b.min).any() || e.cmpgt(b.max).any());
    }
}
