//! Geometry a million units from the origin, where neighbouring `f32` values are 1/16 apart:
//! hit points, box planes and reciprocal directions all lose precision.

use super::grid::push_placed_grid;
use super::scene_of;
use super::sphereflake::push_sphereflake;
use glam::Vec3;
use raytrail_core::scene::Scene;

/// Center of the far scene; every coordinate of the scene lies between 1e5 and 1e6 in magnitude.
pub const FAR_CENTER: Vec3 = Vec3::new(3.0e5, -6.0e5, 9.5e5);

/// A small sphereflake (radius 400, two generations; 10,640 triangles) standing on a shared-edge
/// grid floor (2,000 units wide, 32 x 32 quads; 2,048 triangles), both around [`FAR_CENTER`].
///
/// The floor's vertices are exact in `f32` even out there (steps of 62.5), so rays can still pass
/// exactly through its shared edges; the spheres' vertices are rounded to the 1/16 grid.
pub fn far_from_origin() -> Scene {
    let radius = 400.0;
    let mut tris = Vec::new();
    push_sphereflake(2, 3, FAR_CENTER, radius, &mut tris);
    let floor_y = FAR_CENTER.y - radius;
    push_placed_grid(32, |p| Vec3::new(FAR_CENTER.x + 1000.0 * p.x, floor_y, FAR_CENTER.z + 1000.0 * p.y), &mut tris);
    scene_of(tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_are_far_from_the_origin() {
        let scene = far_from_origin();
        assert_eq!(scene.triangles().len(), 10_640 + 2_048);
        let b = scene.bounds();
        for axis in 0..3 {
            let (lo, hi) = (b.min[axis].abs().min(b.max[axis].abs()), b.min[axis].abs().max(b.max[axis].abs()));
            assert!(lo > 1e5 && hi < 1e6, "axis {axis}: {b:?}");
            assert_eq!(b.min[axis].signum(), b.max[axis].signum());
        }
        // Extent is small against the offset: this is what stresses precision.
        assert!(b.extent().max_element() < 3000.0);
    }
}
