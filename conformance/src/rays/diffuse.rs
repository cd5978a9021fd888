//! Diffuse bounce rays: incoherent secondary rays leaving the primary hit points.

use super::{hit_point, scene_epsilon};
use crate::rng::Pcg32;
use glam::Vec3;
use raytrail_core::scene::Scene;
use raytrail_core::{Hit, Ray};

/// One bounce ray per hit of `rays` (misses, non-finite hits and zero-area triangles skipped), in
/// the order of `rays`.
///
/// The direction is drawn from the cosine-weighted hemisphere around the hit triangle's geometric
/// normal, turned to face the incoming ray; the origin is the hit point pushed off the surface
/// along that normal by [`scene_epsilon`], and `t` runs over `[0, inf]`. The random stream of each
/// ray is keyed by the index of its primary ray, so a ray does not change when other rays start
/// hitting or missing. Panics if `rays` and `hits` differ in length or a hit's primitive is not in
/// `scene`.
pub fn diffuse(rays: &[Ray], hits: &[Hit], scene: &Scene, seed: u64) -> Vec<Ray> {
    assert_eq!(rays.len(), hits.len(), "diffuse: one hit per ray");
    let eps = scene_epsilon(scene.bounds());
    rays.iter()
        .zip(hits)
        .enumerate()
        .filter_map(|(i, (ray, hit))| {
            let p = hit_point(ray, hit)?;
            let t = scene.triangles()[hit.prim as usize];
            let mut n = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]).normalize_or_zero();
            if n == Vec3::ZERO {
                return None;
            }
            if n.dot(ray.dir()) > 0.0 {
                n = -n;
            }
            let mut rng = Pcg32::new(seed, i as u64);
            let dir = cosine_hemisphere(n, rng.in_unit_disk());
            Some(Ray::new(p + n * eps, dir, 0.0, f32::INFINITY))
        })
        .collect()
}

/// A unit direction with density proportional to its cosine with the unit normal `n`, from a
/// uniform point `(x, y)` of the unit disk (Malley: lifted from the disk onto the hemisphere).
fn cosine_hemisphere(n: Vec3, (x, y): (f32, f32)) -> Vec3 {
    let (t, b) = n.any_orthonormal_pair();
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    (t * x + b * y + n * z).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hemisphere_is_cosine_weighted() {
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        let mut rng = Pcg32::new(5, 5);
        let samples = 20_000;
        let mean_cos: f32 = (0..samples)
            .map(|_| {
                let d = cosine_hemisphere(n, rng.in_unit_disk());
                assert!(d.dot(n) >= 0.0);
                d.dot(n)
            })
            .sum::<f32>()
            / samples as f32;
        // E[cos] under a cosine-weighted hemisphere is 2/3 (uniform would be 1/2).
        assert!((mean_cos - 2.0 / 3.0).abs() < 0.01, "{mean_cos}");
    }
}
