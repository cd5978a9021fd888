//! Mesh loading end to end: the real scenes in `shared/scenes`, and malformed files on disk.
//!
//! The scenes folder defaults to `../shared/scenes` beside the workspace; `RAYTRAIL_SCENES`
//! overrides it. A missing large mesh is skipped with a printed line, and fails the test where
//! `RAYTRAIL_REQUIRE_SCENES=1` (`raytrail_conformance::paths::find_mesh`).

mod mesh {
    use raytrail_conformance::paths::find_mesh as scene_file;
    use raytrail_core::scene::Mesh;
    use raytrail_mesh::{self as mesh, load, load_bytes, load_with, LoadOptions};
    use std::io::Write;
    use std::path::{Path, PathBuf};
    use std::time::Instant;

    fn check_scene(file: &str, triangles: usize) {
        let Some(path) = scene_file(file) else { return };
        let start = Instant::now();
        let mesh = load(&path).unwrap_or_else(|e| panic!("{e}"));
        let took = start.elapsed();
        println!("{file}: {} triangles, {} vertices, loaded in {took:.2?}", mesh.triangles.len(), mesh.positions.len());
        assert_eq!(mesh.triangles.len(), triangles, "{file}");
        // Indices in range and coordinates finite.
        mesh.to_scene().unwrap_or_else(|e| panic!("{file}: {e:?}"));
    }

    #[test]
    fn scene_cornell_box() {
        check_scene("cornell_box.obj", 36);
    }

    #[test]
    fn scene_teapot() {
        check_scene("teapot.obj", 6320);
    }

    #[test]
    fn scene_kitchen() {
        check_scene("kitchen.obj", 56939);
    }

    #[test]
    fn scene_sponza() {
        check_scene("sponza.obj", 66450);
    }

    #[test]
    fn scene_bunny() {
        check_scene("bunny.obj", 69666);
    }

    #[test]
    fn scene_dragon_res2() {
        check_scene("dragon_vrip_res2.ply.gz", 202520);
    }

    #[test]
    fn scene_dragon_full() {
        check_scene("dragon_vrip.ply.gz", 871414);
    }

    /// Triangles as corner positions, by a deliberately naive reading of the OBJ: every `f` line
    /// in file order, fan-split. tobj's output must match it exactly.
    fn naive_obj_triangles(text: &str) -> Vec<[[f32; 3]; 3]> {
        let mut v: Vec<[f32; 3]> = Vec::new();
        let mut out = Vec::new();
        for line in text.lines() {
            let mut w = line.split_whitespace();
            match w.next() {
                Some("v") => v.push([0, 1, 2].map(|_| w.next().unwrap().parse().unwrap())),
                Some("f") => {
                    let corners: Vec<[f32; 3]> = w
                        .map(|c| {
                            let i: i64 = c.split('/').next().unwrap().parse().unwrap();
                            v[if i < 0 { v.len() as i64 + i } else { i - 1 } as usize]
                        })
                        .collect();
                    for k in 1..corners.len() - 1 {
                        out.push([corners[0], corners[k], corners[k + 1]]);
                    }
                }
                _ => {}
            }
        }
        out
    }

    #[test]
    fn obj_fans_in_file_order() {
        for file in ["cornell_box.obj", "sponza.obj", "kitchen.obj"] {
            let Some(path) = scene_file(file) else { return };
            let mesh = load(&path).unwrap();
            let got: Vec<[[f32; 3]; 3]> =
                mesh.triangles.iter().map(|t| t.map(|i| mesh.positions[i as usize].to_array())).collect();
            let want = naive_obj_triangles(&std::fs::read_to_string(&path).unwrap());
            assert_eq!(got.len(), want.len(), "{file}");
            let first_diff = got.iter().zip(&want).position(|(a, b)| a != b);
            assert_eq!(first_diff, None, "{file}: triangle order or fan split differs");
        }
    }

    /// Loads `data` from a file named `file` in a scratch folder, removed afterwards, with the
    /// strict policy (every file here is meant to fail or load as a whole).
    fn load_file(file: &str, data: &[u8]) -> (PathBuf, Result<Mesh, mesh::MeshError>) {
        // One folder per call: tests run in parallel, and a shared folder could be removed by one
        // test while another writes into it.
        static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("raytrail-mesh-files-{}-{n}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(file);
        std::fs::write(&path, data).unwrap();
        let result = load_with(&path, &LoadOptions::STRICT).map(|(mesh, _)| mesh);
        let _ = std::fs::remove_dir_all(&dir);
        (path, result)
    }

    fn gzip(data: &[u8]) -> Vec<u8> {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        enc.write_all(data).unwrap();
        enc.finish().unwrap()
    }

    /// Loads `data` from a file named `file` and checks the error starts with the file, then `at`.
    fn fails(file: &str, data: &[u8], at: &str) -> String {
        let (path, result) = load_file(file, data);
        let err = result.expect_err(file).to_string();
        let want = format!("{}{at}", path.display());
        assert!(err.starts_with(&want), "got {err:?}, want it to start with {want:?}");
        err
    }

    const TRI_OBJ: &str = "# a triangle\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    const PLY_HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

    #[test]
    fn obj_face_with_non_number() {
        let e = fails("nan_face.obj", format!("{TRI_OBJ}f 1 2 three\n").as_bytes(), ":6: ");
        assert!(e.contains("face parse error"), "{e}");
    }

    #[test]
    fn obj_truncated_mid_line() {
        let whole = format!("{TRI_OBJ}v 1 1 0\nf 2 4 3\n");
        // Cut inside the last face (an error when strict; by default the short face is skipped),
        // and inside the last vertex.
        let e = fails("cut_face.obj", &whole.as_bytes()[..whole.len() - 3], ":7: ");
        assert!(e.contains("face has 2 vertices"), "{e}");
        assert_eq!(load_bytes(&whole.as_bytes()[..whole.len() - 3], "cut_face.obj").unwrap().triangles.len(), 1);
        let e = fails("cut_vertex.obj", &whole.as_bytes()[..whole.len() - 12], ":6: ");
        assert!(e.contains("position parse error"), "{e}");
    }

    #[test]
    fn ply_bad_header() {
        let bad = PLY_HEAD.replace("property float y", "property flaot y");
        let e = fails("bad_header.ply", bad.as_bytes(), ":5: ");
        assert!(e.contains("unknown property type \"flaot\""), "{e}");
        fails("no_magic.ply", b"format ascii 1.0\n", ":1: not a PLY file");
        fails("no_end.ply", PLY_HEAD.replace("end_header\n", "").as_bytes(), ":8: header ends");
    }

    #[test]
    fn ply_too_few_vertex_lines() {
        let e = fails("few.ply", format!("{PLY_HEAD}0 0 0\n1 0 0\n3 0 1 2\n").as_bytes(), ":12: ");
        assert!(e.contains("vertex 2: more values than the header declares"), "{e}");
        let e = fails("few_end.ply", format!("{PLY_HEAD}0 0 0\n1 0 0\n").as_bytes(), ":11: ");
        assert!(e.contains("file ends after 2 of 3 `vertex` elements"), "{e}");
    }

    #[test]
    fn ply_face_of_two_vertices() {
        let e = fails("two.ply", format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1 0\n2 0 1\n").as_bytes(), ":13: ");
        assert!(e.contains("face 0: face has 2 vertices"), "{e}");
    }

    /// A binary PLY of `mesh` with float coordinates and uchar/int face lists.
    fn binary_ply(mesh: &Mesh, big_endian: bool) -> Vec<u8> {
        let order = if big_endian { "big" } else { "little" };
        let mut out = format!(
            "ply\nformat binary_{order}_endian 1.0\ncomment written by the test\nelement vertex {}\n\
             property float x\nproperty float y\nproperty float z\nelement face {}\n\
             property list uchar int vertex_indices\nend_header\n",
            mesh.positions.len(),
            mesh.triangles.len()
        )
        .into_bytes();
        let word = |le: [u8; 4], be: [u8; 4]| if big_endian { be } else { le };
        for p in &mesh.positions {
            for c in p.to_array() {
                out.extend(word(c.to_le_bytes(), c.to_be_bytes()));
            }
        }
        for t in &mesh.triangles {
            out.push(3);
            for &i in t {
                let i = i as i32;
                out.extend(word(i.to_le_bytes(), i.to_be_bytes()));
            }
        }
        out
    }

    fn sample_mesh() -> Mesh {
        let obj = "v 0 0 0\nv 1.5 0 0\nv 1 1 0.25\nv 0 1 -3\nv 7 8 9\nf 1 2 3 4\nf 5 1 3\n";
        mesh::load_obj(obj.as_bytes(), "sample.obj").unwrap()
    }

    #[test]
    fn ply_binary_round_trip() {
        let mesh = sample_mesh();
        assert_eq!(mesh.triangles.len(), 3);
        for big_endian in [false, true] {
            let data = binary_ply(&mesh, big_endian);
            assert_eq!(load_file("rt.ply", &data).1.unwrap(), mesh, "big_endian={big_endian}");
            assert_eq!(load_bytes(&gzip(&data), "rt.ply.gz").unwrap(), mesh);
            assert_eq!(mesh::load_ply(&data[..], "rt.ply").unwrap(), mesh);
        }
    }

    #[test]
    fn ply_binary_truncated() {
        let data = binary_ply(&sample_mesh(), false);
        let body = data.len() - 5 * 12 - 3 * 13;
        let e = fails("cut.ply", &data[..data.len() - 6], ": byte ");
        let want = format!("byte {}: face 2 of 3 (starting at byte {}): file ends", body + 91, body + 86);
        assert!(e.contains(&want), "{e}\nwant {want}");
        let e = fails("cut_vertex.ply", &data[..body + 18], &format!(": byte {}: vertex 1 of 5", body + 16));
        assert!(e.contains("property `y`: file ends: 4 bytes needed, 2 left"), "{e}");
    }

    #[test]
    fn garbage_bytes() {
        // Deterministic noise that is not valid UTF-8 on its first line.
        let mut x = 0x2545_f491_u32;
        let noise: Vec<u8> = std::iter::once(0xff)
            .chain((0..4096).map(|_| {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                x as u8
            }))
            .collect();
        fails("noise.ply", &noise, ":1: not a PLY file");
        let e = fails("noise.obj", &noise, ":1: ");
        assert!(e.contains("read error"), "{e}");
        let e = fails("noise.bin", &noise, ": ");
        assert!(e.contains("unknown mesh format"), "{e}");
    }

    #[test]
    fn empty_file() {
        fails("empty.obj", b"", ": file is empty");
        fails("empty.ply", b"", ": file is empty");
        fails("empty.ply.gz", &gzip(b""), ": file is empty after gzip");
    }

    #[test]
    fn gzip_corrupt() {
        let mut gz = gzip(format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").as_bytes());
        let n = gz.len();
        gz[12..n - 8].iter_mut().for_each(|b| *b = b.wrapping_mul(31).wrapping_add(7));
        fails("corrupt.ply.gz", &gz, ": gzip data is corrupt or truncated: ");
        fails("corrupt.obj.gz", &gz, ": gzip data is corrupt or truncated: ");
        fails("short.ply.gz", &gz[..n / 2], ": gzip data is corrupt or truncated: ");
    }

    #[test]
    fn missing_file() {
        let path = Path::new("/nonexistent/raytrail/none.obj");
        let e = load(path).unwrap_err().to_string();
        assert!(e.starts_with("/nonexistent/raytrail/none.obj: cannot read file: "), "{e}");
    }
}
