//! Ray hashing (Garanzha & Loop 2010, Sec. 3.1): a ray's origin and direction quantized on two
//! virtual grids and merged into a 32-bit key; rays with equal keys are taken to be coherent.

use super::StreamParams;
use crate::geometry::morton3;
use crate::{Aabb, Ray};
use glam::Vec3;

/// Cells per axis are capped at 2^10 so a cell index fits the Morton code's 10 bits.
const MAX_CELLS: u32 = 1 << 10;

/// The key of a ray no method can trace ([`Ray::is_traceable`]): sorted last, never in a frustum.
pub const UNTRACEABLE_KEY: u32 = u32::MAX;

/// The two virtual grids: origins over the scene box, directions over the faces of the unit cube.
///
/// The paper leaves open how the two cell ids are merged into 32 bits. Here the key is the cell
/// pair itself, direction cell above origin cell, so two rays share a key only when they share
/// both cells. Where the pair needs more than 32 bits, the origin grid is coarsened a Morton level
/// at a time (the lowest three bits of its code dropped: cells twice as wide) until it fits. A
/// hash of the pair would keep the cells but let unrelated rays collide into one packet, and one
/// such packet of three diffuse rays on the dragon had a frustum over 80,000 leaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayGrid {
    /// Lower corner of the origin grid (the scene box's).
    pub lo: Vec3,
    /// `1 / cell size` of the origin grid (0 for a scene of no extent: one cell).
    pub inv_cell: f32,
    /// Origin cells per axis (1 to 1024).
    pub cells: [u32; 3],
    /// Bits of the origin cell's Morton code (3 per bit of the widest axis's cell index).
    pub origin_bits: u32,
    /// Direction cells per side of a cube face (1 to 1024).
    pub dir_cells: u32,
    /// Bits of a position on a face (2 per bit of `dir_cells - 1`).
    pub face_bits: u32,
    /// Low bits of the origin cell's Morton code dropped so the pair fits 32 bits (a multiple of
    /// three; 0 where it fits as it is).
    pub origin_drop: u32,
}

impl RayGrid {
    /// The grids for a scene with bounds `scene` and the cell sizes of `params`.
    pub fn new(scene: &Aabb, params: &StreamParams) -> RayGrid {
        let extent = scene.extent().max(Vec3::ZERO);
        let diagonal = extent.length();
        // Cells at least 1/1024 of the longest side, so that every axis fits its 10 bits.
        let cell = (params.origin_cell_fraction * diagonal).max(extent.max_element() / MAX_CELLS as f32);
        let inv_cell = if cell > 0.0 && cell.is_finite() { 1.0 / cell } else { 0.0 };
        let per_axis = |e: f32| ceil_u32(e * inv_cell).clamp(1, MAX_CELLS);
        let cells = [per_axis(extent.x), per_axis(extent.y), per_axis(extent.z)];
        let widest = cells.iter().copied().max().unwrap_or(1);
        let origin_bits = 3 * (u32::BITS - (widest - 1).leading_zeros());
        let dir_cells = ceil_u32(1.0 / params.direction_cell_fraction).clamp(1, MAX_CELLS);
        let face_bits = 2 * (u32::BITS - (dir_cells - 1).leading_zeros());
        // Six faces need three bits above the position on the face.
        let over = (3 + face_bits + origin_bits).saturating_sub(32);
        let origin_drop = over.div_ceil(3) * 3;
        let lo = if scene.is_empty() { Vec3::ZERO } else { scene.min };
        RayGrid { lo, inv_cell, cells, origin_bits, dir_cells, face_bits, origin_drop }
    }

    /// The ray's 32-bit key ([`UNTRACEABLE_KEY`] for a ray that cannot be traced).
    pub fn key(&self, ray: &Ray) -> u32 {
        if !ray.is_traceable() {
            return UNTRACEABLE_KEY;
        }
        let rel = (ray.origin() - self.lo) * self.inv_cell;
        // `as u32` saturates (and maps NaN to 0), so origins outside the box land in its border cells.
        let cell = |x: f32, n: u32| (x as u32).min(n - 1);
        let origin = morton3(cell(rel.x, self.cells[0]), cell(rel.y, self.cells[1]), cell(rel.z, self.cells[2]));
        let kept = self.origin_bits - self.origin_drop;
        let key = (self.direction_cell(ray.dir()) << kept) | (origin >> self.origin_drop);
        // The untraceable key is reserved (the largest pair is below it: 6 faces, not 8).
        key.min(UNTRACEABLE_KEY - 1)
    }

    /// The direction's cell: the cube face it points through (dominant axis and sign), then its
    /// position on that face, Morton-ordered.
    fn direction_cell(&self, d: Vec3) -> u32 {
        let a = d.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let face = 2 * axis + u32::from(d[axis as usize].is_sign_negative());
        let (u, v) = (d[(axis as usize + 1) % 3] / a[axis as usize], d[(axis as usize + 2) % 3] / a[axis as usize]);
        let n = self.dir_cells;
        let cell = |x: f32| (((x + 1.0) * 0.5 * n as f32) as u32).min(n - 1);
        (face << self.face_bits) | morton2(cell(u), cell(v))
    }
}

/// `x` rounded up to an integer, saturating (`f32::ceil` needs `std`).
fn ceil_u32(x: f32) -> u32 {
    let c = x as u32;
    if (c as f32) < x {
        c.saturating_add(1)
    } else {
        c
    }
}

/// Interleaves the low 10 bits of two values.
fn morton2(x: u32, y: u32) -> u32 {
    fn spread(v: u32) -> u32 {
        let mut v = v & 0x3ff;
        v = (v | (v << 8)) & 0x00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333;
        (v | (v << 1)) & 0x5555_5555
    }
    spread(x) | (spread(y) << 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> RayGrid {
        RayGrid::new(&Aabb::new(Vec3::ZERO, Vec3::splat(1.0)), &StreamParams::default())
    }

    #[test]
    fn nearby_rays_share_a_key_and_far_ones_do_not() {
        let g = grid();
        let r = |o: Vec3, d: Vec3| Ray::new(o, d, 0.0, f32::INFINITY);
        let a = g.key(&r(Vec3::splat(0.5), Vec3::new(1.0, 0.1, 0.2)));
        assert_eq!(a, g.key(&r(Vec3::splat(0.5001), Vec3::new(1.0, 0.1001, 0.2))));
        assert_ne!(a, g.key(&r(Vec3::splat(0.9), Vec3::new(1.0, 0.1, 0.2))), "another origin cell");
        assert_ne!(a, g.key(&r(Vec3::splat(0.5), Vec3::new(-1.0, 0.1, 0.2))), "another cube face");
        assert_ne!(a, g.key(&r(Vec3::splat(0.5), Vec3::new(1.0, 0.5, 0.2))), "another cell on the face");
    }

    #[test]
    fn untraceable_rays_and_outside_origins() {
        let g = grid();
        assert_eq!(g.key(&Ray::new(Vec3::NAN, Vec3::X, 0.0, 1.0)), UNTRACEABLE_KEY);
        assert_eq!(g.key(&Ray::new(Vec3::ZERO, Vec3::ZERO, 0.0, 1.0)), UNTRACEABLE_KEY);
        // Far outside the box: clamped into a border cell, not wrapped around.
        let far = g.key(&Ray::new(Vec3::splat(-1e30), Vec3::X, 0.0, 1.0));
        assert_eq!(far, g.key(&Ray::new(Vec3::ZERO, Vec3::X, 0.0, 1.0)));
    }

    #[test]
    fn a_fine_origin_grid_is_coarsened_to_fit_32_bits() {
        let params =
            StreamParams { origin_cell_fraction: 1e-4, direction_cell_fraction: 1.0 / 64.0, ..StreamParams::default() };
        let g = RayGrid::new(&Aabb::new(Vec3::ZERO, Vec3::splat(1.0)), &params);
        assert_eq!((g.origin_bits, g.face_bits), (30, 12));
        assert_eq!(g.origin_drop, 15, "3 + 12 + 30 - 32 = 13 bits over, rounded up to whole levels");
        // Keys still separate faces and distant origins.
        let r = |o: Vec3, d: Vec3| g.key(&Ray::new(o, d, 0.0, 1.0));
        assert_ne!(r(Vec3::splat(0.2), Vec3::X), r(Vec3::splat(0.2), -Vec3::X));
        assert_ne!(r(Vec3::splat(0.2), Vec3::X), r(Vec3::splat(0.8), Vec3::X));
    }

    #[test]
    fn morton_codes_interleave() {
        assert_eq!(morton3(1, 0, 0), 1);
        assert_eq!(morton3(0, 1, 0), 2);
        assert_eq!(morton3(0, 0, 1), 4);
        assert_eq!(morton3(0x3ff, 0x3ff, 0x3ff), (1 << 30) - 1);
        assert_eq!(morton2(3, 0), 0b0101);
    }
}
