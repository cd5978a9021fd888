//! Uniform random rays: origins anywhere in and around the scene, directions anywhere.

use crate::rng::Pcg32;
use glam::Vec3;
use raytrail_core::scene::Scene;
use raytrail_core::Ray;

/// `n` rays with origins uniform in the scene's box enlarged by a tenth of its largest extent on
/// every side (so some start outside, some inside, and flat scenes get a volume), directions
/// uniform on the unit sphere, and `t` in `[0, inf]`.
pub fn uniform_random(scene: &Scene, n: usize, seed: u64) -> Vec<Ray> {
    let b = scene.bounds();
    let margin = Vec3::splat(match 0.1 * b.extent().max_element() {
        m if m > 0.0 => m,
        _ => 1.0,
    });
    let (lo, hi) = (b.min - margin, b.max + margin);
    let mut rng = Pcg32::new(seed, 0x0F_u64);
    (0..n).map(|_| Ray::new(rng.in_box(lo, hi), rng.unit_vector(), 0.0, f32::INFINITY)).collect()
}
