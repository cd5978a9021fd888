//! A scene moved as an animation moves it, for the refit checks: every vertex pushed away from
//! or pulled toward the scene's centre by a factor that varies with direction and time, so that
//! boxes grow in some places and shrink in others and triangles cross into their neighbours'
//! boxes.

use raytrail_core::geometry::Triangle;
use raytrail_core::scene::Scene;
use raytrail_core::Error;

/// `scene` at time `phase` (0 is no change): each vertex `p` at `c + (p - c) s` for the centre `c`
/// of the scene's box and `s = 1 + 0.2 wave(3 x + phase) - 0.2 wave(phase)`, with `x` the vertex's
/// offset from the centre along the x axis over the box's half extent and `wave` a periodic bump
/// of period 4 between -1 and 1. Deterministic on every machine (no `sin`, whose
/// results differ between math libraries: [`crate::rng`]), and the same vertex moves alike in
/// every triangle that shares it (no cracks open). Fails only where a moved vertex is not finite.
pub fn breathing(scene: &Scene, phase: f32) -> Result<Scene, Error> {
    let b = scene.bounds();
    let (c, half) = ((b.min + b.max) * 0.5, ((b.max - b.min) * 0.5).max_element().max(f32::MIN_POSITIVE));
    let moved = scene
        .triangles()
        .iter()
        .map(|t| Triangle {
            v: t.v.map(|p| {
                let x = (p.x - c.x) / half;
                let s = 1.0 + 0.2 * wave(3.0 * x + phase) - 0.2 * wave(phase);
                c + (p - c) * s
            }),
        })
        .collect();
    Scene::new(moved)
}

/// A periodic bump of period 4: `8 f (1 - f) - 1` for `f` the fractional part of `x / 4`, from -1
/// at each multiple of 4 up to 1 halfway between (`+ - *` and `floor` only: the same bits on
/// every machine).
fn wave(x: f32) -> f32 {
    let f = x / 4.0 - (x / 4.0).floor();
    8.0 * f * (1.0 - f) - 1.0
}
