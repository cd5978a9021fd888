//! The same triangles written as OBJ, OFF, STL (ASCII and binary), PLY (ASCII and binary), GLB and
//! glTF load to identical triangles and give identical hits, bit for bit, with every method on the
//! serial reference backend (issue #19).

use glam::Vec3;
use raytrail_conformance::rays::primary;
use raytrail_conformance::rng::Pcg32;
use raytrail_conformance::SerialBackend;
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::method::{Method, Query};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::scene::{Mesh, Scene};
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::{Hit, Ray};
use raytrail_mesh::{load_with, LoadOptions};
use std::path::PathBuf;
use std::sync::Arc;

#[path = "../../mesh/tests/common/mesh_writers.rs"]
mod mesh_writers;

/// A closed box with a hole-riddled lid and a tilted fan inside: shared vertices, polygons of
/// several sizes written as triangles, awkward floats.
fn sample() -> Mesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut quad = |p: [Vec3; 4], positions: &mut Vec<Vec3>| {
        let b = positions.len() as u32;
        positions.extend(p);
        triangles.push([b, b + 1, b + 2]);
        triangles.push([b, b + 2, b + 3]);
    };
    let (lo, hi) = (Vec3::new(-1.0, -0.5, -2.0 / 3.0), Vec3::new(1.3, 0.7, 0.9));
    let c = |x: bool, y: bool, z: bool| {
        Vec3::new(if x { hi.x } else { lo.x }, if y { hi.y } else { lo.y }, if z { hi.z } else { lo.z })
    };
    for axis in 0..3 {
        for side in [false, true] {
            let f = |a: bool, b: bool| match axis {
                0 => c(side, a, b),
                1 => c(a, side, b),
                _ => c(a, b, side),
            };
            quad([f(false, false), f(true, false), f(true, true), f(false, true)], &mut positions);
        }
    }
    // A fan of thin triangles through the middle, around a shared centre.
    let centre = positions.len() as u32;
    positions.push(Vec3::new(0.1, 0.1, 0.1));
    for k in 0..24 {
        let a = k as f32 * std::f32::consts::TAU / 24.0;
        positions.push(Vec3::new(0.8 * a.cos(), 0.55 * a.sin(), 0.3 * (a * 3.0).sin()));
    }
    for k in 0..24 {
        triangles.push([centre, centre + 1 + k, centre + 1 + (k + 1) % 24]);
    }
    Mesh { positions, triangles }
}

/// Writes the sample in every format (the core tests' writers) into a scratch folder; the files'
/// paths.
fn write_all(m: &Mesh, dir: &std::path::Path) -> Vec<PathBuf> {
    std::fs::create_dir_all(dir).unwrap();
    mesh_writers::every_format(m)
        .into_iter()
        .map(|(f, data)| {
            let path = dir.join(f);
            std::fs::write(&path, data).unwrap();
            path
        })
        .collect()
}

/// A few hundred rays: a primary image of the scene and random rays through its box, some from
/// inside it.
fn rays(scene: &Scene) -> Vec<Ray> {
    let mut rays = primary(scene, 16, 12);
    let b = scene.bounds();
    let mut rng = Pcg32::new(19, 1);
    for k in 0..160 {
        let inside = b.min + (b.max - b.min) * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let dir = Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5);
        let origin = if k % 2 == 0 { inside } else { inside - dir * 10.0 };
        rays.push(Ray::new(origin, dir, 0.0, f32::INFINITY));
    }
    rays
}

fn trace_all(scene: &Scene, rays: &[Ray]) -> Vec<(Method, Query, Vec<Hit>)> {
    let bvh = SahBuilder::default().build(scene.triangles()).unwrap();
    let prepared = PreparedScene::new(scene, bvh, &Method::ALL).unwrap();
    let backend = SerialBackend;
    let prepared = backend.prepare(Arc::new(prepared)).unwrap();
    let mut out = Vec::new();
    for method in Method::ALL {
        for query in Query::ALL {
            let mut hits = vec![Hit::MISS; rays.len()];
            backend.trace(&prepared, rays, &TraceOptions::new(method).query(query), &mut hits).unwrap();
            out.push((method, query, hits));
        }
    }
    out
}

fn bits(h: &Hit) -> [u32; 4] {
    [h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits()]
}

#[test]
fn every_format_gives_the_same_triangles_and_hits() {
    let m = sample();
    let dir = std::env::temp_dir().join(format!("raytrail-conformance-mesh-formats-{}", std::process::id()));
    let files = write_all(&m, &dir);
    assert!(files.len() >= 8, "{} files", files.len());
    let reference = m.to_scene().unwrap();
    let rays = rays(&reference);
    assert!(rays.len() >= 300);
    let want = trace_all(&reference, &rays);
    let hits: usize = want.iter().map(|(_, _, h)| h.iter().filter(|h| h.is_hit()).count()).sum();
    assert!(hits > want.len() * rays.len() / 4, "too few hits to compare: {hits}");
    for path in &files {
        let file = path.display();
        let (mesh, report) = load_with(path, &LoadOptions::STRICT).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(report.skipped, 0);
        let scene = mesh.to_scene().unwrap();
        let same = scene.triangles().iter().zip(reference.triangles()).all(|(a, b)| {
            a.v.iter().flat_map(|v| v.to_array()).map(f32::to_bits).eq(b
                .v
                .iter()
                .flat_map(|v| v.to_array())
                .map(f32::to_bits))
        });
        assert!(same && scene.triangles().len() == reference.triangles().len(), "{file}: triangles differ");
        for ((method, query, got), (_, _, expected)) in trace_all(&scene, &rays).iter().zip(&want) {
            let first = got.iter().zip(expected).position(|(a, b)| bits(a) != bits(b));
            assert_eq!(first, None, "{file}: {method} {query:?}: hits differ from the reference's");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
