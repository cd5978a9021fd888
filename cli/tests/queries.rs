//! The queries beyond closest and any hit on the command line. `trace --all`: every hit along each
//! ray, one record per hit with its ray's index; each ray's first record is the closest hit
//! `trace` writes, the records go ray by ray in order of `t`, and `--max-hits` cuts. `nearest`:
//! the nearest point to each point of a point file, as the library answers it.

mod scratch;

use scratch::Scratch;
use std::path::Path;
use std::process::{Command, Output};

fn run(args: &[&dyn AsRef<std::ffi::OsStr>]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raytrail")).args(args).output().unwrap()
}

/// A fresh folder of the test's own, removed when it passes.
fn folder(name: &str) -> Scratch {
    Scratch::new(&format!("queries-{name}"))
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

#[test]
fn every_hit_ray_by_ray_beginning_with_the_closest() {
    let dir = folder("lists");
    let rays = dir.join("rays.npy");
    let out = run(&[&"rays", &"--scene", &"builtin", &"--out", &rays, &"--width", &"32", &"--height", &"24"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (closest, all, one) = (dir.join("closest.npy"), dir.join("all.npy"), dir.join("one.npy"));
    for (file, extra) in [(&closest, &[][..]), (&all, &["--all"][..]), (&one, &["--all", "--max-hits", "1"][..])] {
        let mut args: Vec<&dyn AsRef<std::ffi::OsStr>> =
            vec![&"trace", &"--scene", &"builtin", &"--rays", &rays, &"--out", file];
        for e in extra {
            args.push(e);
        }
        let out = run(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    let closest = records(&closest, "('t', '<f4'), ('prim', '<u4')", 16);
    let all = records(&all, "('ray', '<u4'), ('t', '<f4')", 20);
    let one = records(&one, "('ray', '<u4'), ('t', '<f4')", 20);
    // Ray by ray, each ray's in order of t.
    for pair in all.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        let (ta, tb) = (f32::from_bits(word(a, 1)), f32::from_bits(word(b, 1)));
        assert!(word(a, 0) < word(b, 0) || (word(a, 0) == word(b, 0) && ta <= tb), "{a:?} {b:?}");
    }
    // Each ray's first record is its closest hit, bit for bit; a miss has none.
    let mut firsts = std::collections::BTreeMap::new();
    for r in &all {
        firsts.entry(word(r, 0)).or_insert((word(r, 1), word(r, 2)));
    }
    let mut hits = 0;
    for (i, c) in closest.iter().enumerate() {
        let first = firsts.get(&(i as u32)).copied();
        if word(c, 0) == f32::INFINITY.to_bits() {
            assert_eq!(first, None, "ray {i}");
        } else {
            assert_eq!(first, Some((word(c, 0), word(c, 1))), "ray {i}");
            hits += 1;
        }
    }
    assert!(hits > 0 && all.len() > hits, "{hits} rays hit, {} records", all.len());
    // --max-hits 1: the closest hits alone.
    assert_eq!(one.len(), hits);
    assert!(one.iter().all(|r| firsts.get(&word(r, 0)) == Some(&(word(r, 1), word(r, 2)))));
}

#[test]
fn the_list_flags_need_all() {
    let out = run(&[&"trace", &"--scene", &"builtin", &"--rays", &"r.npy", &"--out", &"o.npy", &"--max-hits", &"3"]);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    let out = run(&[&"trace", &"--scene", &"builtin", &"--rays", &"r.npy", &"--out", &"o.npy", &"--all", &"--any"]);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
}

/// A float32 `.npy` file of shape (N, 3).
fn write_points(path: &Path, points: &[[f32; 3]]) {
    let dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': ({}, 3), }}", points.len());
    let pad = 64 - (10 + dict.len() + 1) % 64;
    let header = format!("{dict}{}\n", " ".repeat(pad % 64));
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    bytes.extend(points.iter().flatten().flat_map(|x| x.to_le_bytes()));
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn nearest_points_are_the_library_s() {
    let dir = folder("nearest");
    let scene = raytrail_conformance::scenes::sphereflake(3);
    let points = raytrail_conformance::rays::query_points(&scene, 200, 0.5, 5);
    let (file, out) = (dir.join("points.npy"), dir.join("nearest.npy"));
    write_points(&file, &points);
    let run_with = |radius: &str| {
        let out = run(&[&"nearest", &"--scene", &"builtin", &"--points", &file, &"--out", &out, &"--radius", &radius]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    let tracer = raytrail::TracerBuilder::default().build_scene(&scene).unwrap();
    for radius in [f32::INFINITY, 0.2] {
        run_with(&radius.to_string());
        let got = records(&out, "('prim', '<u4'), ('distance', '<f4')", 28);
        let want = tracer.nearest_points(&points, radius).unwrap();
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            let words: Vec<u32> = (0..7).map(|k| word(g, k)).collect();
            match w {
                Some(n) => {
                    let expect = [
                        n.prim,
                        n.distance.to_bits(),
                        n.point[0].to_bits(),
                        n.point[1].to_bits(),
                        n.point[2].to_bits(),
                        n.u.to_bits(),
                        n.v.to_bits(),
                    ];
                    assert_eq!(words, expect);
                }
                None => assert_eq!((words[0], words[1]), (u32::MAX, f32::INFINITY.to_bits())),
            }
        }
        assert_eq!(want.iter().all(Option::is_some), radius == f32::INFINITY);
    }
    let bad = run(&[&"nearest", &"--scene", &"builtin", &"--points", &file, &"--out", &out, &"--radius", &"-1"]);
    assert_eq!(bad.status.code(), Some(2), "{}", String::from_utf8_lossy(&bad.stderr));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--radius"));
}

#[test]
fn the_main_job_times_and_checks_the_queries() {
    let out = run(&[&"run", &"--width", &"32", &"--height", &"24", &"--no-gpu", &"--passes", &"1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}\n{}", String::from_utf8_lossy(&out.stderr));
    for line in ["all hits", "nearest", "refit"] {
        let found =
            text.lines().find(|l| l.trim_start().starts_with(line)).unwrap_or_else(|| panic!("no {line} line: {text}"));
        assert!(found.contains(" 0 of "), "{found}");
    }
}
