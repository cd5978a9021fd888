//! The sphereflake (after Haines' SPD): a sphere carrying nine spheres a third its size, each
//! carrying nine more, and so on; many closed meshes over several scales.

use super::icosphere::{unit_icosphere, UnitSphere};
use super::scene_of;
use glam::Vec3;
use raytrail_core::geometry::Triangle;
use raytrail_core::scene::Scene;

/// A sphereflake of `depth` generations below a unit sphere at the origin.
///
/// The root is an icosphere of subdivision level `depth`, each generation one level coarser (never
/// below the bare icosahedron), so every sphere has about as many triangles per unit of screen.
/// Sizes: depth 2 gives 2,660 triangles, depth 3 gives 25,220 (the suite's size).
pub fn sphereflake(depth: u32) -> Scene {
    let mut tris = Vec::new();
    push_sphereflake(depth, depth, Vec3::ZERO, 1.0, &mut tris);
    scene_of(tris)
}

/// Pushes a sphereflake with `depth` generations below a root sphere at `center` of `radius`,
/// tessellated at `root_level`.
pub(super) fn push_sphereflake(depth: u32, root_level: u32, center: Vec3, radius: f32, out: &mut Vec<Triangle>) {
    let spheres: Vec<UnitSphere> = (0..=root_level).map(unit_icosphere).collect();
    grow(&spheres, depth, root_level, center, radius, Vec3::Y, out);
}

/// One sphere and, below it, its children; `up` points away from the parent.
fn grow(spheres: &[UnitSphere], depth: u32, level: u32, center: Vec3, radius: f32, up: Vec3, out: &mut Vec<Triangle>) {
    push_sphere(&spheres[level as usize], center, radius, out);
    if depth == 0 {
        return;
    }
    let child_radius = radius / 3.0;
    let (t, b) = up.any_orthonormal_pair();
    for dir in child_directions() {
        let d = (t * dir.x + b * dir.y + up * dir.z).normalize();
        let child_center = center + d * (radius + child_radius);
        grow(spheres, depth - 1, level.saturating_sub(1), child_center, child_radius, d, out);
    }
}

/// Nine directions in a frame whose z is the sphere's up: six around the equator (every 60
/// degrees), three raised to about 53 degrees (sine 0.8) midway between them. Children stay clear
/// of each other. Built from `sqrt(3) / 2` and exact fractions, not `sin`/`cos`, so the geometry is
/// the same on every platform.
fn child_directions() -> [Vec3; 9] {
    let h = 3f32.sqrt() / 2.0;
    // (cos, sin) of the azimuths 0, 60, ..., 300 and of 30, 150, 270 degrees.
    let ring = [(1.0, 0.0), (0.5, h), (-0.5, h), (-1.0, 0.0), (-0.5, -h), (0.5, -h)];
    let raised = [(h, 0.5), (-h, 0.5), (0.0, -1.0)];
    let (ce, se) = (0.6, 0.8);
    core::array::from_fn(|k| match k {
        0..6 => Vec3::new(ring[k].0, ring[k].1, 0.0),
        _ => Vec3::new(ce * raised[k - 6].0, ce * raised[k - 6].1, se),
    })
}

/// The unit sphere scaled and moved into place; each vertex transformed once, so the sphere stays
/// watertight.
fn push_sphere(s: &UnitSphere, center: Vec3, radius: f32, out: &mut Vec<Triangle>) {
    let placed: Vec<Vec3> = s.positions.iter().map(|&p| center + p * radius).collect();
    out.extend(s.faces.iter().map(|f| {
        let [a, b, c] = f.map(|i| placed[i as usize]);
        Triangle::new(a, b, c)
    }));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(sphereflake(2).triangles().len(), 320 + 9 * 80 + 81 * 20);
        assert_eq!(sphereflake(3).triangles().len(), 25_220);
        let b = sphereflake(3).bounds();
        // Root radius 1; descendants reach at most 1 + 2/3 + 2/9 + 2/27 < 2 from the center.
        assert!(b.min.cmpgt(Vec3::splat(-2.0)).all() && b.max.cmplt(Vec3::splat(2.0)).all(), "{b:?}");
        assert!(b.max.x > 1.8 && b.max.y > 1.5, "{b:?}");
    }
}
