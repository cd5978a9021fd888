//! The mesh formats of issue #19 end to end: OFF, STL (binary and ASCII) and glTF 2.0 / GLB beside
//! OBJ and PLY, the loading policy (skip and count, or strict), and primitive-id sources.
//!
//! Small files are written here; the real files (a Debian package's test models, see
//! `scripts/fetch_scenes.sh`) are read from `$RAYTRAIL_SCENES`, `shared/scenes` beside the
//! checkout or `scenes/` in it, and their tests are skipped with a printed reason where none of
//! those has them.

use glam::Vec3;
use raytrail_core::scene::Mesh;
use raytrail_mesh::{load, load_bytes, load_bytes_with, load_with, write_sources_csv, LoadOptions, Source};
use std::path::{Path, PathBuf};

/// A real mesh fetched by `scripts/fetch_scenes.sh`, or `None` (with a printed reason) when no
/// scenes folder has it; with `RAYTRAIL_REQUIRE_SCENES=1` a missing file fails the test.
fn fetched(file: &str) -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut dirs: Vec<PathBuf> =
        std::env::var_os("RAYTRAIL_SCENES").filter(|d| !d.is_empty()).map(PathBuf::from).into_iter().collect();
    dirs.extend([root.join("../shared/scenes"), root.join("scenes")]);
    if let Some(path) = dirs.iter().map(|d| d.join(file)).find(|p| p.is_file()) {
        return Some(path);
    }
    let why = format!("not found in {dirs:?} (scripts/fetch_scenes.sh fetches it)");
    assert!(!raytrail_conformance::paths::scenes_required(), "missing test model {file}: {why}");
    raytrail_conformance::paths::say_skipped(file, &why);
    None
}

/// Corners as bit patterns: `-0.0` and `0.0` differ.
fn corner_bits(mesh: &Mesh) -> Vec<[[u32; 3]; 3]> {
    corners(mesh).iter().map(|t| t.map(|v| v.map(f32::to_bits))).collect()
}

#[path = "common/mesh_writers.rs"]
mod mesh_writers;
use mesh_writers::*;

// ------------------------------------------------------------------ the sample

/// A small mesh with shared vertices, awkward floats (thirds, tenths, a negative zero, large and
/// tiny values) and triangles in no particular order.
fn sample() -> Mesh {
    let mut positions = vec![
        Vec3::new(0.0, -0.0, 0.0),
        Vec3::new(1.0 / 3.0, 0.1, -2.5),
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(-7.25, 3.0e-5, 12345.678),
        Vec3::new(0.2, 0.7, -0.3),
        Vec3::new(5.0, -5.0, 0.5),
    ];
    let mut triangles = vec![[0, 1, 2], [2, 1, 3], [4, 5, 0], [3, 5, 4], [1, 4, 2]];
    // A grid of quads (two triangles each) so that rays have something to hit.
    let base = positions.len() as u32;
    for y in 0..8 {
        for x in 0..8 {
            positions.push(Vec3::new(x as f32 * 0.7 - 2.0, y as f32 * 0.55 - 2.0, ((x * y) % 5) as f32 * 0.1));
        }
    }
    for y in 0..7u32 {
        for x in 0..7u32 {
            let v = base + y * 8 + x;
            triangles.push([v, v + 1, v + 9]);
            triangles.push([v, v + 9, v + 8]);
        }
    }
    Mesh { positions, triangles }
}

/// A scratch folder of this test, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new(tag: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("raytrail-mesh-formats-{}-{tag}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    fn write(&self, file: &str, data: &[u8]) -> PathBuf {
        let path = self.0.join(file);
        std::fs::write(&path, data).unwrap();
        path
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

// ------------------------------------------------------------------ the same triangles everywhere

#[test]
fn same_triangles_in_every_format() {
    let m = sample();
    let want = corner_bits(&m);
    let dir = Scratch::new("same");
    let mut files = every_format(&m);
    // An external buffer beside a .gltf, read from the file's folder.
    files.push(("sample_external.gltf", gltf_json(&m, Some("sample%20buffer.bin")).into_bytes()));
    dir.write("sample buffer.bin", &gltf_buffer(&m));
    for (file, data) in &files {
        let path = dir.write(file, data);
        let (mesh, report) = load_with(&path, &LoadOptions { strict: true, sources: true, ..LoadOptions::default() })
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(corner_bits(&mesh), want, "{file}: triangles differ");
        assert_eq!(report.skipped, 0, "{file}");
        assert_eq!(report.sources.len(), m.triangles.len(), "{file}");
        // The scenes compare equal too (the form every method traces).
        assert_eq!(mesh.to_scene().unwrap(), m.to_scene().unwrap(), "{file}");
    }
    // By content, whatever the name (not OBJ, which has no signature, nor a binary STL whose
    // header's count is wrong: only its size and name could tell).
    let by_content =
        |f: &str| !f.ends_with(".obj") && !f.contains("external") && !f.contains("wrong") && f != "sample.stl.gz";
    for (file, data) in files.iter().filter(|(f, _)| by_content(f)) {
        let mesh = load_bytes(data, "unnamed.bin").unwrap_or_else(|e| panic!("{file} by content: {e}"));
        assert_eq!(corner_bits(&mesh), want, "{file} by content");
    }
}

#[test]
fn sources_name_the_face_in_each_format() {
    let m = sample();
    let options = LoadOptions { strict: false, sources: true, ..LoadOptions::default() };
    let sources = |file: &str, data: &[u8]| load_bytes_with(data, file, &options).unwrap().1.sources;
    let n = m.triangles.len() as u64;
    // OBJ: lines (one comment, then the vertices, then the faces).
    let first_face_line = 2 + m.positions.len() as u64;
    assert_eq!(sources("a.obj", &obj(&m)), (0..n).map(|k| Source::Line(first_face_line + k)).collect::<Vec<_>>());
    assert_eq!(sources("a.off", &off(&m)), (0..n).map(Source::Face).collect::<Vec<_>>());
    assert_eq!(sources("a.ply", &ply_binary(&m)), (0..n).map(Source::Face).collect::<Vec<_>>());
    assert_eq!(sources("a.stl", &stl_ascii(&m)), (0..n).map(Source::Facet).collect::<Vec<_>>());
    let g = sources("a.glb", &glb(&m));
    assert_eq!(g[7], Source::Gltf { node: 0, mesh: 0, primitive: 0, triangle: 7 });
    let mut csv = Vec::new();
    write_sources_csv(&mut csv, "a.glb", &g[..2]).unwrap();
    assert_eq!(
        String::from_utf8(csv).unwrap(),
        "prim,file,node,mesh,primitive,triangle\n0,a.glb,0,0,0,0\n1,a.glb,0,0,0,1\n"
    );
}

// ------------------------------------------------------------------ the loading policy

/// An OBJ as architectural exports have it: edges written as two-vertex faces, polylines, points.
const EDGY_OBJ: &str =
    "# edges as faces\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2\nl 2 3\np 4\nf 3 4\nf 4 3 1\n";

#[test]
fn obj_with_edges_lines_and_points_loads_with_a_report() {
    let dir = Scratch::new("edgy");
    let path = dir.write("edgy.obj", EDGY_OBJ.as_bytes());
    let (mesh, report) = load_with(&path, &LoadOptions::default()).unwrap();
    assert_eq!(mesh.triangles, [[0, 1, 2], [0, 2, 3], [3, 2, 0]]);
    assert_eq!(report.skipped, 4);
    let summary = report.summary("edgy.obj").unwrap();
    assert_eq!(
        summary,
        "edgy.obj: skipped 4 elements that are not triangles or polygons, the first at line 7: a face with 2 vertices"
    );
    // `load` is the same lenient load.
    assert_eq!(load(&path).unwrap(), mesh);
    // Strict: the error of before, at the first two-vertex face.
    let e = load_with(&path, &LoadOptions::STRICT).unwrap_err().to_string();
    assert_eq!(e, format!("{}:7: face has 2 vertices; a face needs at least 3", path.display()));
}

#[test]
fn short_faces_in_every_face_format() {
    let strict = |file: &str, data: &[u8]| load_bytes_with(data, file, &LoadOptions::STRICT).unwrap_err().to_string();
    let lenient = |file: &str, data: &[u8]| load_bytes_with(data, file, &LoadOptions::default()).unwrap();
    let off = "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n3 0 1 2\n";
    let (m, r) = lenient("a.off", off.as_bytes());
    assert_eq!((m.triangles.len(), r.skipped), (1, 1));
    assert_eq!(strict("a.off", off.as_bytes()), "a.off:6: face 0: face has 2 vertices; a face needs at least 3");
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
               element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n3 0 1 2\n";
    let (m, r) = lenient("a.ply", ply.as_bytes());
    assert_eq!((m.triangles.len(), r.skipped), (1, 1));
    assert_eq!(strict("a.ply", ply.as_bytes()), "a.ply:13: face 0: face has 2 vertices; a face needs at least 3");
}

// ------------------------------------------------------------------ no panic on hostile input

/// Truncations and byte mutations of every format: each loads or fails with an error, and no
/// loader panics (a panic caught inside a loader would show in the message).
#[test]
fn mutated_files_never_panic() {
    let m = Mesh { positions: sample().positions[..6].to_vec(), triangles: sample().triangles[..5].to_vec() };
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for (file, data) in every_format(&m) {
        if file.ends_with(".obj") || file.ends_with(".gz") {
            continue; // tobj is guarded separately; gzip would only test flate2's checksum
        }
        let check = |data: &[u8], what: &str| {
            let result = std::panic::catch_unwind(|| load_bytes_with(data, file, &LoadOptions::default()));
            let result = result.unwrap_or_else(|_| panic!("{file} ({what}): the loader panicked"));
            if let Err(e) = result {
                assert!(!e.to_string().contains("panicked"), "{file} ({what}): {e}");
            }
        };
        for cut in (0..data.len()).step_by(data.len() / 97 + 1) {
            check(&data[..cut], &format!("cut at {cut}"));
        }
        for round in 0..300 {
            let mut bad = data.clone();
            for _ in 0..1 + round % 4 {
                let at = (next() % bad.len() as u64) as usize;
                bad[at] = match next() % 4 {
                    0 => 0xff,
                    1 => b'9',
                    2 => bad[at] ^ (1 << (next() % 8)),
                    _ => 0,
                };
            }
            check(&bad, &format!("mutation {round}"));
        }
    }
}

#[test]
fn gltf_external_buffers() {
    let m = sample();
    let dir = Scratch::new("external");
    let path = dir.write("ext.gltf", gltf_json(&m, Some("ext.bin")).as_bytes());
    let e = load(&path).unwrap_err().to_string();
    let want = format!("{}: meshes[0].primitives[0].attributes.POSITION: buffers[0]: cannot read ", path.display());
    assert!(e.starts_with(&want), "{e}");
    // A buffer file shorter than its byteLength.
    dir.write("ext.bin", &gltf_buffer(&m)[..100]);
    let e = load(&path).unwrap_err().to_string();
    assert!(e.contains("buffers[0]: byteLength is"), "{e}");
    // One longer is read only as far as byteLength.
    let mut long = gltf_buffer(&m);
    long.extend([0u8; 1000]);
    dir.write("ext.bin", &long);
    assert_eq!(corner_bits(&load(&path).unwrap()), corner_bits(&m));
    // A folder where the file should be.
    std::fs::remove_file(dir.0.join("ext.bin")).unwrap();
    std::fs::create_dir(dir.0.join("ext.bin")).unwrap();
    let e = load(&path).unwrap_err().to_string();
    assert!(e.contains("is not a file"), "{e}");
}

// ------------------------------------------------------------------ real files

#[test]
fn real_off_wuson() {
    let Some(path) = fetched("Wuson.off") else { return };
    let (mesh, report) = load_with(&path, &LoadOptions::STRICT).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((mesh.triangles.len(), mesh.positions.len(), report.skipped), (3732, 3205, 0));
    mesh.to_scene().unwrap();
    // A naive reading of the same text gives the same triangles.
    let text = std::fs::read_to_string(&path).unwrap();
    let w: Vec<&str> = text.split_whitespace().collect();
    let (nv, nf) = (w[1].parse::<usize>().unwrap(), w[2].parse::<usize>().unwrap());
    let v: Vec<[f32; 3]> = (0..nv).map(|i| [0, 1, 2].map(|k| w[4 + 3 * i + k].parse().unwrap())).collect();
    let mut at = 4 + 3 * nv;
    let mut want = Vec::new();
    for _ in 0..nf {
        let n: usize = w[at].parse().unwrap();
        let f: Vec<usize> = w[at + 1..at + 1 + n].iter().map(|s| s.parse().unwrap()).collect();
        (1..n - 1).for_each(|k| want.push([v[f[0]], v[f[k]], v[f[k + 1]]]));
        at += 1 + n;
    }
    assert_eq!(corners(&mesh), want);
}

#[test]
fn real_stl_spider_ascii_and_binary_agree() {
    let (Some(ascii), Some(binary)) = (fetched("Spider_ascii.stl"), fetched("Spider_binary.stl")) else { return };
    let a = load_with(&ascii, &LoadOptions::STRICT).unwrap_or_else(|e| panic!("{e}")).0;
    let b = load_with(&binary, &LoadOptions::STRICT).unwrap_or_else(|e| panic!("{e}")).0;
    assert_eq!((a.triangles.len(), b.triangles.len()), (1368, 1368));
    // The ASCII file prints the binary's floats to six or seven digits.
    let worst = corners(&a)
        .iter()
        .zip(corners(&b))
        .flat_map(|(x, y)| (0..9).map(move |k| (x[k / 3][k % 3] - y[k / 3][k % 3]).abs()))
        .fold(0f32, f32::max);
    assert!(worst < 1e-5, "largest difference {worst}");
    a.to_scene().unwrap();
    b.to_scene().unwrap();
}

#[test]
fn real_glb_engine_with_node_transforms() {
    let Some(path) = fetched("2CylinderEngine.glb") else { return };
    let (mesh, report) = load_with(&path, &LoadOptions { strict: true, sources: true, ..LoadOptions::default() })
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(mesh.triangles.len(), 121_496);
    let scene = mesh.to_scene().unwrap();
    // Bounds and mean corner of the transformed triangles, computed independently (in f64, from
    // the file's JSON and buffer, composing the 82 nodes' matrices and TRS transforms).
    let b = scene.bounds();
    let want_lo = [-371.6922629127621, -180.9715576171875, -139.9999929500657];
    let want_hi = [371.69216918961064, 92.04156168904416, 127.99999618810878];
    let mut sum = [0f64; 3];
    for t in scene.triangles() {
        for v in t.v {
            (0..3).for_each(|k| sum[k] += f64::from(v[k]));
        }
    }
    let mean = sum.map(|s| s / (3.0 * 121_496.0));
    let want_mean = [-135.22157350067266, -12.895960336241815, -12.47741672996924];
    for k in 0..3 {
        assert!((f64::from(b.min[k]) - want_lo[k]).abs() < 1e-3, "min {k}: {:?}", b.min);
        assert!((f64::from(b.max[k]) - want_hi[k]).abs() < 1e-3, "max {k}: {:?}", b.max);
        assert!((mean[k] - want_mean[k]).abs() < 1e-3, "mean {k}: {mean:?}");
    }
    // 67 nodes place a mesh; the sources name them in depth-first order.
    let mut nodes: Vec<u32> = report
        .sources
        .iter()
        .map(|s| match s {
            Source::Gltf { node, .. } => *node,
            other => panic!("{other:?}"),
        })
        .collect();
    nodes.dedup();
    assert_eq!(nodes.len(), 67);
}

#[test]
fn real_gltf_primitive_modes() {
    // Strip and fan, without and with indices: two triangles over the unit square, same winding.
    for n in ["04", "05", "11", "12"] {
        let Some(path) = fetched(&format!("Mesh_PrimitiveMode_{n}.gltf")) else { return };
        let mesh = load_with(&path, &LoadOptions::STRICT).unwrap_or_else(|e| panic!("{e}")).0;
        let t = corners(&mesh);
        assert_eq!(t.len(), 2, "{n}");
        let normal = |c: &[[f32; 3]; 3]| {
            let [a, b, c] = c.map(Vec3::from_array);
            (b - a).cross(c - a)
        };
        let (n0, n1) = (normal(&t[0]), normal(&t[1]));
        assert!(n0.z.abs() == 1.0 && n1.z == n0.z, "{n}: areas and winding {n0} {n1}");
    }
    // Lines: nothing to trace, one primitive skipped; an error when strict.
    let Some(path) = fetched("Mesh_PrimitiveMode_01.gltf") else { return };
    let (mesh, report) = load_with(&path, &LoadOptions::default()).unwrap();
    assert_eq!((mesh.triangles.len(), report.skipped), (0, 1));
    assert_eq!(report.first_skipped.unwrap().what, "a primitive in LINES mode");
    let e = load_with(&path, &LoadOptions::STRICT).unwrap_err().to_string();
    assert!(e.ends_with("meshes[0].primitives[0]: a primitive in LINES mode is not triangles"), "{e}");
}
