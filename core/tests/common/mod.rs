//! What the core's integration tests share: a tiny deterministic generator and a triangle soup.
//!
//! Each test file uses a part of it; the rest would be dead code there.
#![allow(dead_code)]

use glam::Vec3;
use raytrail_core::geometry::Triangle;

/// A linear congruential generator: deterministic, no dependency.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in `[0, 1)`.
    pub fn f(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }

    /// Uniform in the unit cube.
    pub fn v(&mut self) -> Vec3 {
        Vec3::new(self.f(), self.f(), self.f())
    }
}

/// `n` random triangles in a 10-unit cube, edges up to `size` long.
pub fn soup(n: usize, seed: u64, size: f32) -> Vec<Triangle> {
    let mut r = Rng(seed);
    (0..n)
        .map(|_| {
            let c = r.v() * 10.0;
            let s = 0.05 + r.f() * size;
            Triangle::new(c, c + (r.v() - 0.5) * s, c + (r.v() - 0.5) * s)
        })
        .collect()
}

/// A mesh of the suite ([`raytrail_conformance::paths::find_mesh`]): `None`, after one printed
/// line saying why, when it is missing, unless `RAYTRAIL_REQUIRE_SCENES=1` makes that a failure.
pub fn scene_file(file: &str) -> Option<std::path::PathBuf> {
    raytrail_conformance::paths::find_mesh(file)
}

/// A soup of `n` triangles (edges up to 1.5) collapsed 4-wide by the pull-up and 8-wide by
/// `eight`, with the scene scale (largest coordinate magnitude) traversals need.
pub fn wide_soup(
    n: usize,
    seed: u64,
    eight: raytrail_core::method::Collapse,
) -> (f32, raytrail_core::wide::WideBvh<4>, raytrail_core::wide::WideBvh<8>) {
    use raytrail_core::bvh2::{SahBuilder, SahConfig};
    use raytrail_core::wide::WideBvh;
    let tris = soup(n, seed, 1.5);
    let scale = tris.iter().flat_map(|t| t.v).map(|v| v.abs().max_element()).fold(0.0, f32::max);
    let bvh = SahBuilder::new(SahConfig::default()).build(&tris).unwrap();
    let w4 = WideBvh::<4>::build(&bvh, &tris, raytrail_core::method::Collapse::PullUp).unwrap();
    let w8 = WideBvh::<8>::build(&bvh, &tris, eight).unwrap();
    (scale, w4, w8)
}

/// Rays from all around a soup in the box 0..12 in every direction (incoherent), every seventh
/// axis-parallel, every third ending at 5; with `zero_every`, every such ray from the first has no direction (untraceable).
pub fn scattered_rays(n: usize, seed: u64, zero_every: Option<usize>) -> Vec<raytrail_core::Ray> {
    let mut r = Rng(seed);
    (0..n)
        .map(|i| {
            let mut d = r.v() - 0.5;
            if i % 7 == 0 {
                d = Vec3::new(0.0, d.y, 0.0);
            }
            if zero_every.is_some_and(|k| i % k == 0) {
                d = Vec3::ZERO;
            }
            raytrail_core::Ray::new(r.v() * 14.0 - 2.0, d, 0.0, if i % 3 == 0 { 5.0 } else { f32::INFINITY })
        })
        .collect()
}
