//! The same triangles written as OBJ, OFF, STL (ASCII and binary), PLY (ASCII and binary), GLB and
//! glTF load to identical triangles and give identical hits, bit for bit, with every method on the
//! serial reference backend (issue #19).

use glam::Vec3;
use raytrail_conformance::rays::primary;
use raytrail_conformance::rng::Pcg32;
use raytrail_conformance::SerialBackend;
use raytrail_core::bvh2::SahBuilder;
use raytrail_core::mesh::{load_with, LoadOptions};
use raytrail_core::method::{Method, Query};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::scene::{Mesh, Scene};
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::{Hit, Ray};
use std::path::PathBuf;
use std::sync::Arc;

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

fn corners(m: &Mesh) -> Vec<[[f32; 3]; 3]> {
    m.triangles.iter().map(|t| t.map(|i| m.positions[i as usize].to_array())).collect()
}

fn text(m: &Mesh, head: String, vertex: &str, face: &str) -> Vec<u8> {
    let mut s = head;
    m.positions.iter().for_each(|p| s += &format!("{vertex}{} {} {}\n", p.x, p.y, p.z));
    let one = usize::from(face == "f ");
    m.triangles
        .iter()
        .for_each(|t| s += &format!("{face}{} {} {}\n", t[0] as usize + one, t[1] as usize + one, t[2] as usize + one));
    s.into_bytes()
}

fn ply_head(m: &Mesh, format: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        m.positions.len(),
        m.triangles.len()
    )
}

fn ply_binary(m: &Mesh) -> Vec<u8> {
    let mut out = ply_head(m, "binary_big_endian").into_bytes();
    m.positions.iter().flat_map(|p| p.to_array()).for_each(|c| out.extend(c.to_be_bytes()));
    for t in &m.triangles {
        out.push(3);
        t.iter().for_each(|i| out.extend(i.to_be_bytes()));
    }
    out
}

fn stl_ascii(m: &Mesh) -> Vec<u8> {
    let mut s = String::from("solid sample\n");
    for t in corners(m) {
        s += "facet normal 0 0 1\nouter loop\n";
        t.iter().for_each(|v| s += &format!("vertex {} {} {}\n", v[0], v[1], v[2]));
        s += "endloop\nendfacet\n";
    }
    (s + "endsolid sample\n").into_bytes()
}

fn stl_binary(m: &Mesh) -> Vec<u8> {
    let mut out = vec![0u8; 80];
    // A wrong count, as some exporters leave it.
    out.extend(0u32.to_le_bytes());
    for t in corners(m) {
        out.extend([0u8; 12]);
        t.iter().flatten().for_each(|c| out.extend(c.to_le_bytes()));
        out.extend([0u8; 2]);
    }
    out
}

/// glTF JSON of the mesh as one indexed primitive, and its buffer (positions then u16 indices).
fn gltf(m: &Mesh, uri: Option<&str>) -> (String, Vec<u8>) {
    let mut bin: Vec<u8> = m.positions.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
    let pl = bin.len();
    bin.extend(m.triangles.iter().flatten().flat_map(|&i| (i as u16).to_le_bytes()));
    let il = bin.len() - pl;
    let uri = uri.map_or(String::new(), |u| format!(r#","uri":"{u}""#));
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"mode":4}}]}}],
"buffers":[{{"byteLength":{len}{uri}}}],
"bufferViews":[{{"buffer":0,"byteLength":{pl}}},{{"buffer":0,"byteOffset":{pl},"byteLength":{il}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{nv},"type":"VEC3"}},
{{"bufferView":1,"componentType":5123,"count":{ni},"type":"SCALAR"}}]}}"#,
        len = bin.len(),
        nv = m.positions.len(),
        ni = 3 * m.triangles.len()
    );
    (json, bin)
}

fn glb(m: &Mesh) -> Vec<u8> {
    let (json, mut bin) = gltf(m, None);
    let mut json = json.into_bytes();
    json.resize(json.len().div_ceil(4) * 4, b' ');
    bin.resize(bin.len().div_ceil(4) * 4, 0);
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((28 + json.len() + bin.len()) as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// Writes the sample in every format into a scratch folder; the files' paths.
fn write_all(m: &Mesh, dir: &std::path::Path) -> Vec<PathBuf> {
    let (json, bin) = gltf(m, Some("sample.bin"));
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("sample.obj", text(m, "o sample\n".into(), "v ", "f ")),
        ("sample.off", text(m, format!("OFF\n{} {} 0\n", m.positions.len(), m.triangles.len()), "", "3 ")),
        ("sample_ascii.ply", text(m, ply_head(m, "ascii"), "", "3 ")),
        ("sample_binary.ply", ply_binary(m)),
        ("sample_ascii.stl", stl_ascii(m)),
        ("sample_binary.stl", stl_binary(m)),
        ("sample.glb", glb(m)),
        ("sample.gltf", json.into_bytes()),
        ("sample.bin", bin),
    ];
    std::fs::create_dir_all(dir).unwrap();
    files
        .into_iter()
        .map(|(f, data)| {
            let path = dir.join(f);
            std::fs::write(&path, data).unwrap();
            path
        })
        .filter(|p| p.extension().is_some_and(|e| e != "bin"))
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
    assert_eq!(files.len(), 8);
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
