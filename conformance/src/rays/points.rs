//! Query points for the nearest-point checks and benches: uniform in the scene's box grown on
//! every side, so some lie inside the mesh's hull, some on no side of it and some far away.

use crate::rng::Pcg32;
use raytrail_core::scene::Scene;

/// `n` points uniform in `scene`'s box grown by `grow` times its size on each side, from `seed`.
pub fn query_points(scene: &Scene, n: usize, grow: f32, seed: u64) -> Vec<[f32; 3]> {
    let b = scene.bounds();
    let pad = (b.max - b.min) * grow;
    let mut rng = Pcg32::new(seed, 0x9e37);
    (0..n).map(|_| rng.in_box(b.min - pad, b.max + pad).to_array()).collect()
}
