//! The stress cases of issue 15's list, and the regressions it reported.

use crate::paths::load_mesh_scene;
use crate::rng::Pcg32;
use crate::scenes::icosphere::unit_icosphere;
use glam::Vec3;
use raytrail_core::geometry::Triangle;
use raytrail_core::Ray;

/// Rays per generated case (modest: the suite runs in debug builds on two cores).
const RAYS: usize = 256;

/// One stress case: a scene, rays, and what the rays may do besides agree.
#[derive(Clone, Debug)]
pub struct StressCase {
    /// Short name.
    pub name: String,
    /// The triangles (primitive id = index).
    pub triangles: Vec<Triangle>,
    /// The rays.
    pub rays: Vec<Ray>,
    /// Rays from inside a closed mesh: a miss is always wrong.
    pub must_hit: bool,
    /// Whether a ray may be refused (false inside the supported range: exact answers only).
    pub may_refuse: bool,
    /// Whether every ray must be refused (just outside the supported range).
    pub must_refuse: bool,
}

impl StressCase {
    fn new(name: impl Into<String>, triangles: Vec<Triangle>, rays: Vec<Ray>) -> Self {
        Self { name: name.into(), triangles, rays, must_hit: false, may_refuse: false, must_refuse: false }
    }
}

/// A closed unit icosphere (320 triangles), its vertices mapped by `f`.
fn sphere(f: impl Fn(Vec3) -> Vec3) -> Vec<Triangle> {
    let s = unit_icosphere(2);
    s.faces.iter().map(|f3| Triangle { v: f3.map(|i| f(s.positions[i as usize])) }).collect()
}

fn ray(o: Vec3, d: Vec3) -> Ray {
    Ray::new(o, d, 0.0, f32::INFINITY)
}

/// Rays from `distance` scene sizes away (along random directions) aimed at random points of
/// random triangles.
fn from_afar(tris: &[Triangle], center: Vec3, size: f32, distance: f32, seed: u64) -> Vec<Ray> {
    let mut rng = Pcg32::new(seed, 15);
    (0..RAYS)
        .map(|_| {
            let t = tris[rng.index(tris.len())];
            let (a, b) = (rng.next_f32(), rng.next_f32());
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let target = t.v[0] + (t.v[1] - t.v[0]) * a + (t.v[2] - t.v[0]) * b;
            let dir = rng.unit_vector();
            let origin = center + (target - center) - dir * (distance * size);
            ray(origin, dir)
        })
        .collect()
}

/// Rays aimed exactly at a vertex of a random triangle from 2 to 4 scene sizes away, running
/// across that triangle nearly in its plane (tilted by `2^-12 .. 2^-4`): a watertight test errs
/// across the ray, and a graze stretches that error along the face, so these test the verdict's
/// tolerance model as much as the methods (the Python tests' exact judgement found such rays).
/// The first is the teapot ray those tests found (vertex 1 of face 4909).
fn vertex_grazes(tris: &[Triangle], size: f32, seed: u64) -> Vec<Ray> {
    let mut rng = Pcg32::new(seed, 15);
    let found = ray(Vec3::new(-9.9667635, 4.953761, 0.5745586), Vec3::new(10.941785, -2.479361, -1.2901136));
    let grazes = (0..RAYS * 4).filter_map(|i| {
        let tri = tris[rng.index(tris.len())];
        let vertex = tri.v[rng.index(3)];
        let normal = (tri.v[1] - tri.v[0]).cross(tri.v[2] - tri.v[0]).try_normalize()?;
        let across = ((tri.v[0] + tri.v[1] + tri.v[2]) / 3.0 - vertex).try_normalize()?;
        let tilt = (2.0f32).powi(-12 + (i % 9) as i32) * if i % 2 == 0 { 1.0 } else { -1.0 };
        let dir = (across + normal * tilt).try_normalize()?;
        Some(ray(vertex - dir * (size * rng.range_f32(2.0, 4.0)), dir))
    });
    std::iter::once(found).chain(grazes).take(RAYS).collect()
}

/// Every case, teapot regressions included (the teapot from the scenes folder; an error names
/// it when missing).
pub fn all_cases() -> Result<Vec<StressCase>, crate::paths::SceneFileError> {
    let mut out = Vec::new();
    let unit = sphere(|p| p);
    // Rays from the centre through every vertex and every edge's midpoint of a closed mesh: each
    // lands exactly on a shared vertex or (up to the midpoint's rounding) a shared edge.
    let s = unit_icosphere(2);
    let mut aimed: Vec<Ray> = s.positions.iter().map(|&p| ray(Vec3::ZERO, p)).collect();
    for f in &s.faces {
        for i in 0..3 {
            let (a, b) = (s.positions[f[i] as usize], s.positions[f[(i + 1) % 3] as usize]);
            aimed.push(ray(Vec3::ZERO, (a + b) * 0.5));
            // And from off-centre, so the ray is not along a symmetry of the mesh.
            aimed.push(ray(Vec3::new(0.125, -0.0625, 0.25), (a + b) * 0.5 - Vec3::new(0.125, -0.0625, 0.25)));
        }
    }
    out.push(StressCase {
        must_hit: true,
        ..StressCase::new("shared vertices and edges, closed mesh", unit.clone(), aimed)
    });

    // Grazing rays: along the faces of a flat grid of shared edges, barely tilted.
    let grid: Vec<Triangle> = (0..8)
        .flat_map(|i| (0..8).map(move |j| (i as f32, j as f32)))
        .flat_map(|(x, y)| {
            let p = |dx: f32, dy: f32| Vec3::new((x + dx) / 8.0, (y + dy) / 8.0, 0.0);
            [Triangle::new(p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)), Triangle::new(p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0))]
        })
        .collect();
    let mut rng = Pcg32::new(7, 15);
    let grazing = (0..RAYS)
        .map(|i| {
            let tilt = f32::EPSILON * (1 << (i % 20)) as f32;
            let o = Vec3::new(-0.5, rng.next_f32(), tilt * 2.0);
            ray(o, Vec3::new(1.0, rng.range_f32(-0.1, 0.1), -tilt))
        })
        .collect();
    out.push(StressCase::new("grazing rays", grid.clone(), grazing));

    // Axis-parallel rays with signed zeros, aimed at grid lines and vertices.
    let mut axis = Vec::new();
    for i in 0..=8 {
        for j in 0..=8 {
            let (x, y) = (i as f32 / 8.0, j as f32 / 8.0 + if i % 2 == 0 { 0.0 } else { 1.0 / 16.0 });
            for (dx, dy) in [(0.0, 0.0), (-0.0, 0.0), (0.0, -0.0), (-0.0, -0.0)] {
                axis.push(ray(Vec3::new(x, y, 1.0), Vec3::new(dx, dy, -1.0)));
                axis.push(ray(Vec3::new(x, y, -1.0), Vec3::new(dx, dy, 1.0)));
            }
        }
    }
    out.push(StressCase::new("axis-parallel rays with signed zeros", grid, axis));

    // Origins from 1 to 1e8 scene sizes away.
    for (k, d) in [1.0f32, 1e2, 1e4, 1e6, 1e8].into_iter().enumerate() {
        out.push(StressCase::new(
            format!("origins {d:e} diameters away"),
            unit.clone(),
            from_afar(&unit, Vec3::ZERO, 2.0, d, 100 + k as u64),
        ));
    }

    // Scaled scenes (1e-30 to 1e30), rays from inside (must hit) and from outside.
    for (k, s) in [1e-30f32, 1e-12, 1e12, 1e30].into_iter().enumerate() {
        let tris = sphere(|p| p * s);
        let mut rng = Pcg32::new(200 + k as u64, 15);
        let inside: Vec<Ray> = (0..RAYS).map(|_| ray(Vec3::ZERO, rng.unit_vector())).collect();
        out.push(StressCase {
            must_hit: true,
            ..StressCase::new(format!("scaled by {s:e}, from inside"), tris.clone(), inside)
        });
        out.push(StressCase::new(
            format!("scaled by {s:e}, from outside"),
            tris.clone(),
            from_afar(&tris, Vec3::ZERO, 2.0 * s, 3.0, 300 + k as u64),
        ));
    }

    // Translated up to 1e7 diameters from the origin.
    for (k, t) in [1e3f32, 1e5, 1e7].into_iter().enumerate() {
        let c = Vec3::new(t * 2.0, -t, t * 0.5);
        let tris = sphere(|p| p + c);
        out.push(StressCase::new(
            format!("translated {t:e} diameters"),
            tris.clone(),
            from_afar(&tris, c, 2.0, 3.0, 400 + k as u64),
        ));
    }

    // Subnormal coordinates (a sphere of radius 1e-40).
    let tiny = sphere(|p| p * 1e-40);
    let mut rng = Pcg32::new(500, 15);
    let inside: Vec<Ray> = (0..RAYS).map(|_| ray(Vec3::ZERO, rng.unit_vector())).collect();
    out.push(StressCase { must_hit: true, ..StressCase::new("subnormal coordinates, from inside", tiny, inside) });

    // A tiny triangle beside a huge one (and the unit triangle beside one of 1e14).
    for (big, name) in [(1e6f32, "tiny triangles beside huge ones"), (1e14, "unit triangle beside one of 1e14")] {
        let tris = vec![
            Triangle::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)),
            Triangle::new(Vec3::new(-big, -big, -big), Vec3::new(big, -big, -big), Vec3::new(0.0, big, -big)),
        ];
        let mut rng = Pcg32::new(600, 15);
        let rays = (0..RAYS)
            .map(|_| ray(Vec3::new(rng.range_f32(-0.5, 1.5), rng.range_f32(-0.5, 1.5), 1.0), Vec3::NEG_Z))
            .collect();
        out.push(StressCase::new(name, tris, rays));
    }

    // The supported range's edges: just inside (exact answers, no refusal) and just outside
    // (every ray refused and counted). Far origins: up to 2^32 scene magnitudes; directions: down
    // to about 1e-35 of the scene's size.
    let edge = |d: f32, dirs: f32| -> Vec<Ray> {
        let mut rng = Pcg32::new(700, 15);
        (0..64)
            .map(|_| {
                let dir = rng.unit_vector();
                let target = Vec3::new(rng.range_f32(-0.3, 0.3), rng.range_f32(-0.3, 0.3), rng.range_f32(-0.3, 0.3));
                ray(target - dir * d, dir * dirs)
            })
            .collect()
    };
    out.push(StressCase::new("range edge: origins 1e9 away (inside)", unit.clone(), edge(1e9, 1.0)));
    out.push(StressCase {
        must_refuse: true,
        may_refuse: true,
        ..StressCase::new("range edge: origins 1e10 away (outside)", unit.clone(), edge(1e10, 1.0))
    });
    out.push(StressCase::new("range edge: directions of 1e-33 (inside)", unit.clone(), edge(1.5, 1e-33)));
    out.push(StressCase {
        must_refuse: true,
        may_refuse: true,
        ..StressCase::new("range edge: directions of 1e-37 (outside)", unit.clone(), edge(1.5, 1e-37))
    });

    // Regressions from issue 15, on the teapot.
    let teapot = load_mesh_scene("teapot.obj")?.scene.triangles().to_vec();
    let bounds = teapot.iter().fold(raytrail_core::Aabb::EMPTY, |b, t| b.union(t.bounds()));
    let (c, size) = (bounds.center(), bounds.extent().length());
    for (k, d) in [1e5f32, 1e6, 1e7, 1e8].into_iter().enumerate() {
        out.push(StressCase::new(
            format!("teapot, origins {d:e} diameters away"),
            teapot.clone(),
            from_afar(&teapot, c, size, d, 800 + k as u64),
        ));
    }
    out.push(StressCase::new(
        "teapot, vertex-aimed grazes from 2-4 sizes away",
        teapot.clone(),
        vertex_grazes(&teapot, size, 1000),
    ));
    let big: Vec<Triangle> = teapot.iter().map(|t| Triangle { v: t.v.map(|p| p * 1e11) }).collect();
    out.push(StressCase::new("teapot scaled by 1e11", big.clone(), from_afar(&big, c * 1e11, size * 1e11, 2.0, 900)));
    // The camera's rays (unit directions) into the teapot at 1e37 and 1e-40: `raytrail rays` wrote
    // NaN directions there, and at 1e37 the unit directions, scaled with their origins, were
    // refused as unreliable.
    for (scale, name) in [(1e37f32, "teapot at 1e37, camera rays"), (1e-40, "teapot at 1e-40, camera rays")] {
        let scaled: Vec<Triangle> = teapot.iter().map(|t| Triangle { v: t.v.map(|p| p * scale) }).collect();
        if let Some(bounds) = scaled.iter().map(Triangle::bounds).reduce(raytrail_core::Aabb::union) {
            let camera = crate::rays::primary_from(&crate::rays::Camera::framing(bounds), 16, 16);
            out.push(StressCase::new(name, scaled, camera));
        }
    }
    Ok(out)
}

/// The names of [`all_cases`], for reports.
pub fn case_names() -> Result<Vec<String>, crate::paths::SceneFileError> {
    Ok(all_cases()?.into_iter().map(|c| c.name).collect())
}
