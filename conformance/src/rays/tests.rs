use super::*;
use crate::scenes::{shared_edge_grid, sphereflake};
use raytrail_core::intersect::{TriangleTest, Watertight};

/// Reference closest hits: every ray against every triangle with the watertight test.
fn brute_force(scene: &Scene, rays: &[Ray]) -> Vec<Hit> {
    rays.iter()
        .map(|r| {
            let mut best = Hit::MISS;
            if !r.is_traceable() {
                return best;
            }
            let pr = Watertight::prepare(r);
            for (i, t) in scene.triangles().iter().enumerate() {
                if let Some(h) = Watertight::intersect(&pr, t.v[0], t.v[1], t.v[2], r.tmin, r.tmax) {
                    if best.is_beaten_by(h.t, i as u32) {
                        best = Hit { t: h.t, prim: i as u32, u: h.u, v: h.v };
                    }
                }
            }
            best
        })
        .collect()
}

/// Rays as bit patterns, so NaNs compare equal to themselves.
fn bits(rays: &[Ray]) -> Vec<[u32; 8]> {
    rays.iter()
        .map(|r| {
            let [ox, oy, oz] = r.origin.map(f32::to_bits);
            let [dx, dy, dz] = r.dir.map(f32::to_bits);
            [ox, oy, oz, r.tmin.to_bits(), dx, dy, dz, r.tmax.to_bits()]
        })
        .collect()
}

fn small_sets(scene: &Scene) -> Vec<RaySet> {
    let size = RaySetSize { width: 32, height: 24, uniform_count: 500 };
    ray_sets(scene, size, &mut |rays| brute_force(scene, rays))
}

#[test]
fn ray_sets_are_deterministic_and_complete() {
    let scene = sphereflake(2);
    let (a, b) = (small_sets(&scene), small_sets(&scene));
    assert_eq!(a.iter().map(|s| s.kind).collect::<Vec<_>>(), RaySetKind::ALL);
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(bits(&x.rays), bits(&y.rays), "{} differs between runs", x.kind);
        assert!(!x.rays.is_empty(), "{} is empty", x.kind);
    }
    assert_eq!(a[0].rays.len(), 32 * 24);
    assert_eq!(a[3].rays.len(), 500);
    // Seeds matter.
    assert_ne!(bits(&uniform_random(&scene, 100, 1)), bits(&uniform_random(&scene, 100, 2)));
    assert_ne!(bits(&adversarial(&scene, 1)), bits(&adversarial(&scene, 2)));
}

#[test]
fn primary_rays_follow_morton_order() {
    let scene = sphereflake(1);
    let rays = primary(&scene, 8, 4);
    let cam = Camera::framing(scene.bounds());
    let order = morton_order(8, 4);
    assert_eq!(&order[..5], &[(0, 0), (1, 0), (0, 1), (1, 1), (2, 0)]);
    for (r, &(x, y)) in rays.iter().zip(&order) {
        assert_eq!(*r, cam.ray(x as f32 + 0.5, y as f32 + 0.5, 8, 4));
    }
    // The middle of the image looks at the scene.
    let hits = brute_force(&scene, &primary(&scene, 16, 16));
    let n = hits.iter().filter(|h| h.is_hit()).count();
    assert!(n > 32, "{n} of 256 hit");
}

#[test]
fn shadow_rays_go_to_the_light() {
    let scene = sphereflake(2);
    let rays = primary(&scene, 32, 32);
    let hits = brute_force(&scene, &rays);
    let light = default_light(scene.bounds());
    let eps = scene_epsilon(scene.bounds());
    let shadows = shadow(&rays, &hits, light, eps);
    assert_eq!(shadows.len(), hits.iter().filter(|h| h.is_hit()).count());
    let diag = scene.bounds().extent().length();
    for s in &shadows {
        let end = s.origin() + s.dir();
        assert!((end - light).length() < 1e-5 * diag, "{s:?} ends at {end}, not {light}");
        assert!(s.tmin > 0.0 && s.tmin < s.tmax && s.tmax < 1.0);
        assert!(s.is_traceable());
    }
    // Each starts where its primary ray hit.
    let hit_rays: Vec<(&Ray, &Hit)> = rays.iter().zip(&hits).filter(|(_, h)| h.is_hit()).collect();
    for (s, (r, h)) in shadows.iter().zip(hit_rays) {
        assert!((s.origin() - (r.origin() + r.dir() * h.t)).length() < 1e-5 * diag);
    }
}

#[test]
fn diffuse_rays_leave_the_surface_on_the_incoming_side() {
    let scene = sphereflake(2);
    let rays = primary(&scene, 32, 32);
    let hits = brute_force(&scene, &rays);
    let bounces = diffuse(&rays, &hits, &scene, 3);
    assert_eq!(bounces.len(), hits.iter().filter(|h| h.is_hit()).count());
    assert_ne!(bits(&bounces), bits(&diffuse(&rays, &hits, &scene, 4)));
    let hit_rays = rays.iter().zip(&hits).filter(|(_, h)| h.is_hit());
    for (b, (r, h)) in bounces.iter().zip(hit_rays) {
        let t = scene.triangles()[h.prim as usize];
        let n = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
        // Same side as the incoming ray's origin: against the incoming direction.
        assert!(b.dir().dot(n) * r.dir().dot(n) <= 0.0);
        assert!((b.dir().length() - 1.0).abs() < 1e-5);
        assert_eq!(b.tmax, f32::INFINITY);
    }
    // The bounces see the scene again: a sphereflake is concave between its spheres.
    assert!(brute_force(&scene, &bounces).iter().any(Hit::is_hit));
}

#[test]
fn uniform_origins_fill_the_enlarged_box() {
    let scene = shared_edge_grid(4);
    let b = scene.bounds();
    let rays = uniform_random(&scene, 2000, 11);
    let m = 0.1 * b.extent().max_element();
    let outside = rays.iter().filter(|r| r.origin().cmplt(b.min).any() || r.origin().cmpgt(b.max).any()).count();
    assert!(outside > 0 && outside < rays.len());
    for r in &rays {
        assert!(r.origin().cmpge(b.min - m).all() && r.origin().cmple(b.max + m).all());
        assert!((r.dir().length() - 1.0).abs() < 1e-5);
    }
}

#[test]
fn adversarial_set_has_every_hazard() {
    let scene = shared_edge_grid(8);
    let rays = adversarial(&scene, RAY_SEED);
    assert!((300..5000).contains(&rays.len()), "{} rays", rays.len());
    let any = |f: &dyn Fn(&Ray) -> bool| rays.iter().any(f);
    let comps = |r: &Ray| r.origin.into_iter().chain(r.dir).chain([r.tmin, r.tmax]).collect::<Vec<f32>>();
    assert!(any(&|r| r.origin.iter().any(|x| x.is_nan())));
    assert!(any(&|r| r.dir.iter().any(|x| x.is_nan())));
    assert!(any(&|r| r.tmin.is_nan() || r.tmax.is_nan()));
    assert!(any(&|r| r.dir.iter().any(|x| x.is_infinite())));
    assert!(any(&|r| r.origin.iter().any(|x| x.is_infinite())));
    assert!(any(&|r| r.dir().is_finite() && r.dir() == Vec3::ZERO));
    assert!(any(&|r| r.tmin > r.tmax));
    assert!(any(&|r| r.tmin == r.tmax));
    assert!(any(&|r| r.tmin < 0.0));
    assert!(any(&|r| r.tmax == 0.0 && r.tmax.is_sign_positive()));
    assert!(any(&|r| r.tmax == 0.0 && r.tmax.is_sign_negative()));
    assert!(any(&|r| r.dir().length() > 1e25 && r.dir().is_finite()));
    assert!(any(&|r| r.dir().length() < 1e-35 && r.dir() != Vec3::ZERO));
    // Axis-parallel with each signed zero in each slot.
    for axis in 0..3 {
        let zero_in = |neg: bool| {
            any(&|r| {
                r.dir[axis] == 0.0 && r.dir[axis].is_sign_negative() == neg && r.dir.iter().any(|&x| x.abs() == 1.0)
            })
        };
        assert!(zero_in(true) && zero_in(false), "axis {axis}");
    }
    // Origins exactly on the scene box's planes.
    let b = scene.bounds();
    assert!(any(&|r| (0..3).any(|a| r.origin[a] == b.min[a] || r.origin[a] == b.max[a])));
    // Traceable rays dominate, so the set exercises traversal, not only the early-out.
    let traceable = rays.iter().filter(|r| r.is_traceable()).count();
    assert!(traceable * 2 > rays.len());
    // No NaN sneaks in where a finite value was meant: finite rays are all finite.
    assert!(rays.iter().all(|r| comps(r).iter().all(|x| !x.is_nan()) || !r.is_traceable()));
}

#[test]
fn rays_through_grid_vertices_do_not_slip_through() {
    // Axis-parallel rays (with a -0.0 component) through the flat grid's shared vertices must hit:
    // the reference the suite's sets are checked against is watertight.
    let scene = shared_edge_grid(8);
    let b = scene.bounds();
    let rays: Vec<Ray> = (0..=8)
        .flat_map(|i| (0..=8).map(move |j| (i, j)))
        .map(|(i, j)| {
            let (x, y) = (i as f32 * 0.25 - 1.0, j as f32 * 0.25 - 1.0);
            Ray::new(Vec3::new(x, y, b.min.z - 1.0), Vec3::new(-0.0, 0.0, 1.0), 0.0, 2.0)
        })
        .collect();
    let hits = brute_force(&scene, &rays);
    assert!(hits.iter().all(|h| h.is_hit() && h.t == 1.0), "{hits:?}");
}

#[test]
fn epsilon_tracks_scale_and_offset() {
    let near = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let far = Aabb::new(Vec3::splat(1e6 - 1.0), Vec3::splat(1e6 + 1.0));
    assert!(scene_epsilon(near) < 1e-4);
    // Several ulps at 1e6 (1/16 each).
    assert!(scene_epsilon(far) > 0.25);
}

#[test]
fn every_generated_and_tiny_scene_gets_its_sets() {
    let mut scenes = crate::scenes::generated();
    scenes.extend(crate::scenes::tiny_cases());
    let size = RaySetSize { width: 8, height: 6, uniform_count: 16 };
    for s in &scenes {
        let sets = ray_sets(&s.scene, size, &mut |rays| brute_force(&s.scene, rays));
        assert_eq!(sets.len(), 5, "{}", s.name);
        assert_eq!(sets[0].rays.len(), 48, "{}", s.name);
        assert!(sets[4].rays.len() > 100, "{}", s.name);
    }
}
