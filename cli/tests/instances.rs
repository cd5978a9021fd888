//! `trace` on a scene file of instances (a JSON file of mesh paths and placements): each hit
//! names its instance's id, an instance placed by the identity answers as the mesh itself, ray
//! masks (`--masks`) pick the instances a ray enters, and a file that is wrong says where.

mod scratch;

use scratch::Scratch;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn run(args: &[&dyn AsRef<std::ffi::OsStr>]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raytrail")).args(args).output().unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A fresh folder of the test's own, removed when it passes.
fn folder(name: &str) -> Scratch {
    Scratch::new(&format!("instances-{name}"))
}

/// The records of a `.npy` file of version 1 whose header holds `descr`, `size` bytes each.
fn records(path: &Path, descr: &str, size: usize) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + len]).unwrap();
    assert!(header.contains(descr), "{header}");
    let body = &bytes[10 + len..];
    assert_eq!(body.len() % size, 0);
    body.chunks(size).map(<[u8]>::to_vec).collect()
}

fn word(r: &[u8], k: usize) -> u32 {
    u32::from_le_bytes([r[4 * k], r[4 * k + 1], r[4 * k + 2], r[4 * k + 3]])
}

/// Camera rays of the built-in scene, written into `dir`.
fn camera_rays(dir: &Path) -> PathBuf {
    let rays = dir.join("rays.npy");
    let out = run(&[&"rays", &"--scene", &"builtin", &"--out", &rays, &"--width", &"32", &"--height", &"24"]);
    assert!(out.status.success(), "{}", stderr(&out));
    rays
}

#[test]
fn an_instance_placed_by_the_identity_answers_as_its_mesh_and_names_its_id() {
    let dir = folder("identity");
    let rays = camera_rays(&dir);
    // The built-in scene where it is (id 5), and a copy 1000 units aside that no camera ray meets.
    let scene = dir.join("scene.json");
    std::fs::write(
        &scene,
        r#"{"meshes": ["builtin"], "instances": [
            {"mesh": 0, "id": 5},
            {"mesh": 0, "id": 9, "transform": [[1, 0, 0, 1000], [0, 1, 0, 0], [0, 0, 1, 0]]}
        ]}"#,
    )
    .unwrap();
    let (flat, placed) = (dir.join("flat.npy"), dir.join("placed.npy"));
    for (s, out_file) in [(Path::new("builtin"), &flat), (scene.as_path(), &placed)] {
        let out = run(&[&"trace", &"--scene", &s, &"--rays", &rays, &"--out", out_file, &"--method", &"bvh8-sah"]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let flat = records(&flat, "('t', '<f4'), ('prim', '<u4')", 16);
    let placed = records(&placed, "('instance', '<u4')", 20);
    assert_eq!(flat.len(), placed.len());
    let mut hits = 0;
    for (f, p) in flat.iter().zip(&placed) {
        // t, prim, u and v bit for bit: the identity maps each ray onto itself.
        assert_eq!(&p[..16], &f[..], "a hit differs from the mesh's own");
        if word(p, 1) != u32::MAX {
            assert_eq!(word(p, 4), 5, "a hit names instance {}", word(p, 4));
            hits += 1;
        }
    }
    assert!(hits >= 50, "only {hits} of {} rays hit: the test would show little", placed.len());
}

#[test]
fn a_moved_instance_is_hit_where_it_was_moved() {
    let dir = folder("moved");
    let rays = camera_rays(&dir);
    // Only a copy moved 1000 units aside: the camera rays miss it all.
    let aside = dir.join("aside.json");
    std::fs::write(
        &aside,
        r#"{"meshes": ["builtin"], "instances": [{"mesh": 0, "transform": [[1, 0, 0, 1000], [0, 1, 0, 0], [0, 0, 1, 0]]}]}"#,
    )
    .unwrap();
    let hits = dir.join("hits.npy");
    let out = run(&[&"trace", &"--scene", &aside, &"--rays", &rays, &"--out", &hits]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(records(&hits, "('instance', '<u4')", 20).iter().all(|r| word(r, 1) == u32::MAX));
}

#[test]
fn a_wrong_scene_file_says_what_is_wrong() {
    let dir = folder("wrong");
    let rays = camera_rays(&dir);
    let hits = dir.join("hits.npy");
    for (body, expect) in [
        (r#"{"meshes": ["builtin"], "instances": [{"mesh": 0}, {"mesh": 3}]}"#, "instance 1 names mesh 3"),
        (r#"{"meshes": ["builtin"], "instances": [{"mesh": 0, "trasform": []}]}"#, "unknown field `trasform`"),
        (r#"{"meshes": ["builtin"], "instances": []}"#, "no instances"),
        (r#"{"meshes": ["missing.obj"], "instances": [{"mesh": 0}]}"#, "missing.obj"),
        (
            r#"{"meshes": ["builtin"], "instances": [{"mesh": 0, "transform": [[1, 0, 0, 0], [1, 0, 0, 0], [0, 0, 1, 0]]}]}"#,
            "not invertible",
        ),
        (r#"{"meshes": ["builtin"], "instances": [{"mesh": 0}"#, "line 1"),
    ] {
        let scene = dir.join("scene.json");
        std::fs::write(&scene, body).unwrap();
        let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--out", &hits]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{body}: {err}");
        assert!(err.contains(expect) && err.contains("scene.json"), "{body}: {err}");
        assert!(!hits.exists(), "{body}: a hits file was written");
    }
}

#[test]
fn an_output_naming_a_mesh_of_the_scene_file_is_refused_and_the_mesh_kept() {
    let dir = folder("output");
    let rays = camera_rays(&dir);
    let mesh = dir.join("triangle.obj");
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::fs::write(&mesh, text).unwrap();
    let scene = dir.join("scene.json");
    std::fs::write(&scene, r#"{"meshes": ["triangle.obj"], "instances": [{"mesh": 0}]}"#).unwrap();
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--out", &mesh]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("destroy the input"), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(&mesh).unwrap(), text);
    // Every hit along a ray is not offered for instances yet: refused, not silently closest.
    let hits = dir.join("hits.npy");
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--out", &hits, &"--all"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--all is not available"), "{}", stderr(&out));
}

/// A `.npy` file of `u4` masks, one per ray, written by hand (the layout `numpy.save` writes).
fn write_masks(path: &Path, masks: &[u32]) {
    let mut header = format!("{{'descr': '<u4', 'fortran_order': False, 'shape': ({},), }}", masks.len());
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    bytes.extend(masks.iter().flat_map(|m| m.to_le_bytes()));
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn ray_masks_pick_the_instances_a_ray_may_enter() {
    let dir = folder("masks");
    let rays = camera_rays(&dir);
    let n = records(&rays, "'<f4'", 32).len();
    // Two copies of the built-in scene in one place: mask 1 (id 3) and mask 2 (id 4).
    let scene = dir.join("scene.json");
    std::fs::write(
        &scene,
        r#"{"meshes": ["builtin"], "instances": [{"mesh": 0, "id": 3, "mask": 1}, {"mesh": 0, "id": 4, "mask": 2}]}"#,
    )
    .unwrap();
    let (masks, hits) = (dir.join("masks.npy"), dir.join("hits.npy"));
    // Even rays see only the second copy, odd rays only the first.
    write_masks(&masks, &(0..n).map(|i| if i % 2 == 0 { 2 } else { 1 }).collect::<Vec<_>>());
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--out", &hits, &"--masks", &masks]);
    assert!(out.status.success(), "{}", stderr(&out));
    let got = records(&hits, "('instance', '<u4')", 20);
    let mut seen = [0; 2];
    for (i, r) in got.iter().enumerate() {
        if word(r, 1) != u32::MAX {
            let want = if i % 2 == 0 { 4 } else { 3 };
            assert_eq!(word(r, 4), want, "ray {i} hit instance {} through its mask", word(r, 4));
            seen[i % 2] += 1;
        }
    }
    assert!(seen.iter().all(|&k| k >= 25), "hits per mask {seen:?}: the test would show little");
    // A mask of no shared bit enters nothing.
    write_masks(&masks, &vec![4; n]);
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--out", &hits, &"--masks", &masks]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(records(&hits, "('instance', '<u4')", 20).iter().all(|r| word(r, 1) == u32::MAX));
}

#[test]
fn wrong_masks_say_what_is_wrong() {
    let dir = folder("wrong-masks");
    let rays = camera_rays(&dir);
    let scene = dir.join("scene.json");
    std::fs::write(&scene, r#"{"meshes": ["builtin"], "instances": [{"mesh": 0}]}"#).unwrap();
    let (masks, hits) = (dir.join("masks.npy"), dir.join("hits.npy"));
    write_masks(&masks, &[1, 2, 3]);
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--out", &hits, &"--masks", &masks]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("holds 3 masks") && err.contains("one mask per ray"), "{err}");
    // On a mesh, masks have nothing to pick.
    let out = run(&[&"trace", &"--scene", &"builtin", &"--rays", &rays, &"--out", &hits, &"--masks", &masks]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("--masks needs a scene file of instances"), "{err}");
    // A float array is not a mask file.
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--out", &hits, &"--masks", &rays]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("unsigned integer"), "{err}");
    assert!(!hits.exists(), "a hits file was written");
}
