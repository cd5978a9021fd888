//! A camera inside the scene, as in a walk through an interior such as Sponza's atrium or a
//! kitchen: the bench's second view beside [`Camera::framing`].
//!
//! It is placed from the scene's bounding box alone: its up axis is +y (the OBJ convention) unless
//! another axis of the box is under half as long as y, then that one (a z-up file); the eye is at
//! the box's centre, lowered to [`Camera::INSIDE_EYE_HEIGHT`] of the box's height above its floor;
//! it looks along the longer of the two horizontal axes, towards +, with a 90-degree vertical field
//! of view (wider across for wide images). Sponza's y and z extents are within 6% of each other,
//! so the shortest extent alone would not tell its up axis.

use super::Camera;
use raytrail_core::Aabb;

impl Camera {
    /// `tan` of half the inside camera's vertical field of view: 90 degrees.
    pub const INSIDE_TAN_HALF_VFOV: f32 = 1.0;

    /// Height of the inside camera's eye above the box's floor, as a fraction of the box's height.
    pub const INSIDE_EYE_HEIGHT: f32 = 0.25;

    /// The camera inside `bounds` (module documentation).
    pub fn inside(bounds: Aabb) -> Camera {
        let (min, extent) = (bounds.min, bounds.extent());
        let up = up_axis(extent.to_array());
        let (a, b) = match up {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        let forward = if extent[b] > extent[a] { b } else { a };
        let mut eye = bounds.center();
        eye[up] = min[up] + Self::INSIDE_EYE_HEIGHT * extent[up];
        let mut target = eye;
        target[forward] += extent[forward].max(1.0);
        let mut up_dir = glam::Vec3::ZERO;
        up_dir[up] = 1.0;
        Camera { eye, target, up: up_dir, tan_half_vfov: Self::INSIDE_TAN_HALF_VFOV }
    }
}

/// The up axis of a box with extents `e`: y, unless another axis is under half as long.
pub fn up_axis(e: [f32; 3]) -> usize {
    let shortest = if e[0] < e[2] { 0 } else { 2 };
    if e[shortest] < 0.5 * e[1] {
        shortest
    } else {
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn the_inside_camera_stands_low_in_the_box_and_looks_along_its_long_side() {
        // Sponza's box: y up although z is (slightly) shorter; x is the long side.
        let sponza = Aabb::new(Vec3::new(-17.4, -0.9, -7.8), Vec3::new(17.4, 15.6, 7.8));
        let c = Camera::inside(sponza);
        assert!((c.eye - Vec3::new(0.0, -0.9 + 16.5 / 4.0, 0.0)).length() < 1e-4, "{}", c.eye);
        assert_eq!((c.target - c.eye).normalize(), Vec3::X);
        assert_eq!(c.up, Vec3::Y);
        assert_eq!(c.tan_half_vfov, 1.0);
        // The eye is inside the box.
        assert!(c.eye.cmpgt(sponza.min).all() && c.eye.cmplt(sponza.max).all());
        // A z-up box, longer along y: z is up, the camera looks along +y.
        let flat = Aabb::new(Vec3::ZERO, Vec3::new(4.0, 10.0, 2.0));
        let c = Camera::inside(flat);
        assert_eq!((c.up, (c.target - c.eye).normalize()), (Vec3::Z, Vec3::Y));
        assert!((c.eye - Vec3::new(2.0, 5.0, 0.5)).length() < 1e-6);
        // The middle ray of the image looks straight ahead.
        let r = c.ray(50.0, 50.0, 100, 100);
        assert!((r.dir() - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn up_is_y_unless_another_axis_is_under_half_as_long() {
        assert_eq!(up_axis([34.8, 16.6, 15.6]), 1);
        assert_eq!(up_axis([10.0, 10.0, 3.0]), 2);
        assert_eq!(up_axis([2.0, 10.0, 10.0]), 0);
    }
}
