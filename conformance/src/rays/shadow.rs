//! Shadow rays: any-hit queries from the primary hit points towards a point light.

use super::hit_point;
use glam::Vec3;
use raytrail_core::{Hit, Ray};

/// One shadow ray per hit of `rays` (misses and non-finite hits skipped), in the order of `rays`.
///
/// Each ray starts at the hit point with the unnormalized direction `light - p`, so the light is
/// at `t = 1`; the interval `[epsilon / |light - p|, 1 - epsilon / |light - p|]` leaves out a
/// distance `epsilon` at both ends (the surface the ray leaves and the light itself). Points within
/// `2 * epsilon` of the light give no ray. Panics if `rays` and `hits` differ in length.
pub fn shadow(rays: &[Ray], hits: &[Hit], light: Vec3, epsilon: f32) -> Vec<Ray> {
    assert_eq!(rays.len(), hits.len(), "shadow: one hit per ray");
    rays.iter()
        .zip(hits)
        .filter_map(|(ray, hit)| {
            let p = hit_point(ray, hit)?;
            let dir = light - p;
            let len = dir.length();
            // Also rejects a NaN or infinite length.
            if !len.is_finite() || len <= 2.0 * epsilon {
                return None;
            }
            let rel = epsilon / len;
            Some(Ray::new(p, dir, rel, 1.0 - rel))
        })
        .collect()
}
