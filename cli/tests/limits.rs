//! What a mesh file may expand to (issue 55): a glTF that places one mesh on thousands of nodes
//! asks for gigabytes from a file of one megabyte; the command refuses it by `--max-triangles`
//! with status 1 and one line, before the copies are allocated, where it used to abort.

mod scratch;

use scratch::Scratch;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh folder of the test's own, removed when it passes.
fn folder(name: &str) -> Scratch {
    Scratch::new(&format!("limits-{name}"))
}

/// The command line with its address space limited to `bytes`, as `ulimit -v` would.
fn limited(bytes: u64, args: &[&dyn AsRef<std::ffi::OsStr>]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_raytrail"));
    command.args(args);
    // SAFETY: setrlimit is async-signal-safe and touches no state of the parent.
    unsafe {
        command.pre_exec(move || {
            let limit = libc::rlimit { rlim_cur: bytes, rlim_max: bytes };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    command.output().unwrap()
}

/// The reported file's shape: `nodes` nodes each placing one mesh of `triangles` triangles that
/// share no vertex (a non-indexed primitive), its buffer in `bomb.bin` beside it.
fn instancing_bomb(dir: &Path, nodes: usize, triangles: usize) -> PathBuf {
    let vertices = 3 * triangles;
    let bin: Vec<u8> = (0..vertices).flat_map(|i| [i as f32, (i % 3) as f32, 0.0]).flat_map(f32::to_le_bytes).collect();
    std::fs::write(dir.join("bomb.bin"), &bin).unwrap();
    let node_list = vec![r#"{"mesh":0}"#; nodes].join(",");
    let roots: Vec<String> = (0..nodes).map(|i| i.to_string()).collect();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{},"uri":"bomb.bin"}}],
"bufferViews":[{{"buffer":0,"byteLength":{}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{vertices},"type":"VEC3"}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
"nodes":[{node_list}],"scenes":[{{"nodes":[{}]}}]}}"#,
        bin.len(),
        bin.len(),
        roots.join(",")
    );
    let path = dir.join("bomb.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

#[test]
fn a_gltf_instancing_bomb_is_refused_by_its_triangle_count_not_an_abort() {
    let dir = folder("bomb");
    // 20,000 nodes x 6,320 triangles: 126 million triangles and 4.55 GB of placed vertices.
    let bomb = instancing_bomb(&dir, 20_000, 6_320);
    let size = std::fs::metadata(&bomb).unwrap().len() + std::fs::metadata(dir.join("bomb.bin")).unwrap().len();
    assert!(size < 1 << 20, "{size} bytes");
    let out = limited(4 << 30, &[&"rays", &"--scene", &bomb, &"--out", &dir.join("r.npy")]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "status {:?}: {err}", out.status);
    // Stopped at the first placement past the limit: the 10,619th.
    assert!(
        err.contains("the scene's nodes place at least 67112080 triangles, more than the limit of 67108864"),
        "{err}"
    );
    assert!(err.contains("--max-triangles") && !err.contains("panicked"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!dir.join("r.npy").exists());
}

#[test]
fn max_triangles_is_a_flag_of_the_command_line() {
    let dir = folder("flag");
    let obj = dir.join("quads.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 3 4\n").unwrap();
    let rays = |max: &str| {
        limited(u64::MAX, &[&"rays", &"--scene", &obj, &"--out", &dir.join("r.npy"), &"--max-triangles", &max])
    };
    let out = rays("3");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = rays("2");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("the `f` lines make 3 triangles, more than the limit of 2"), "{err}");
}
