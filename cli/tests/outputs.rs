//! Outputs that never destroy what they should not (issue 55): an output naming an input is
//! refused before any work, a link's target is written and the link kept, a device or a fifo is
//! written in place and never replaced, a killed run's temporary file does not pile up, and a full
//! stdout ends the command with status 1 and one line instead of a panic.

mod scratch;

use raytrail_conformance::paths::mesh_path;
use scratch::Scratch;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raytrail"))
}

/// A fresh folder of the test's own, removed when it passes.
fn folder(name: &str) -> Scratch {
    Scratch::new(&format!("outputs-{name}"))
}

fn run(args: &[&dyn AsRef<std::ffi::OsStr>]) -> Output {
    bin().args(args).output().unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A copy of the Cornell box and a small ray file made from it, in `dir`.
fn scene_and_rays(dir: &Path) -> (PathBuf, PathBuf) {
    let scene = dir.join("box.obj");
    std::fs::copy(mesh_path("cornell_box.obj"), &scene).unwrap();
    let rays = dir.join("rays.npy");
    let out = run(&[&"rays", &"--scene", &scene, &"--out", &rays, &"--width", &"8", &"--height", &"6"]);
    assert!(out.status.success(), "{}", stderr(&out));
    (scene, rays)
}

/// A usage error (status 2) naming the clash, with `kept` unchanged.
fn refused(out: &Output, kept: &Path, before: &[u8]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("error:") && !err.contains("panicked"), "{err}");
    assert_eq!(std::fs::read(kept).unwrap(), before, "{} was changed", kept.display());
}

#[test]
fn an_output_naming_an_input_is_refused_and_the_input_kept() {
    let dir = folder("inputs");
    let (scene, rays) = scene_and_rays(&dir);
    let (scene_bytes, ray_bytes) = (std::fs::read(&scene).unwrap(), std::fs::read(&rays).unwrap());
    // The ray file as the output.
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--out", &rays]);
    refused(&out, &rays, &ray_bytes);
    assert!(stderr(&out).contains("--out") && stderr(&out).contains("--rays"), "{}", stderr(&out));
    // The scene by another name: a hard link and a spelling through the folder's `.`.
    let link = dir.join("same-box.obj");
    std::fs::hard_link(&scene, &link).unwrap();
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--out", &link]);
    refused(&out, &scene, &scene_bytes);
    let dotted = dir.join(".").join("box.obj");
    for (args, scene_flag) in [
        (vec!["rays", "--out"], Some("--scene")),
        (vec!["render", "--width", "8", "--height", "6", "--out"], Some("--scene")),
        (vec!["explain", "--width", "8", "--height", "6", "--json"], None),
        (vec!["bench", "--width", "8", "--height", "6", "--json"], Some("--scene")),
    ] {
        let mut cmd = bin();
        cmd.args(&args).arg(&dotted).args(scene_flag).arg(&scene);
        let out = cmd.output().unwrap();
        refused(&out, &scene, &scene_bytes);
    }
    // Two outputs naming one file, before either exists.
    let hits = dir.join("hits.npy");
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--out", &hits, &"--prim-map", &hits]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(!hits.exists());
}

#[cfg(unix)]
#[test]
fn a_link_is_followed_and_a_device_or_fifo_written_in_place() {
    use std::os::unix::fs::FileTypeExt;
    let dir = folder("links");
    let (scene, rays) = scene_and_rays(&dir);
    // A link: its target gets the hits, the link stays a link.
    let (target, link) = (dir.join("target.npy"), dir.join("link.npy"));
    std::fs::write(&target, b"old").unwrap();
    std::os::unix::fs::symlink("target.npy", &link).unwrap();
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--method", &"stack", &"--out", &link]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert!(std::fs::read(&target).unwrap().starts_with(b"\x93NUMPY"));
    // /dev/null: written, still the device (as root a rename would have replaced it).
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--method", &"stack", &"--out", &"/dev/null"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(std::fs::metadata("/dev/null").unwrap().file_type().is_char_device());
    // A fifo: a reader gets the whole file, and the fifo stays a fifo.
    let fifo = dir.join("hits.fifo");
    let c_path = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid, NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c_path.as_ptr(), 0o600) }, 0);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    let out = run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--method", &"stack", &"--out", &fifo]);
    assert!(out.status.success(), "{}", stderr(&out));
    let got = reader.join().unwrap();
    assert_eq!(got, std::fs::read(&target).unwrap(), "the fifo's reader got other bytes than the file");
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
}

#[test]
fn a_killed_runs_temporary_file_is_cleared_by_the_next_run() {
    let dir = folder("stale");
    let (scene, rays) = scene_and_rays(&dir);
    // As `kill -9` in the middle of writing hits.npy leaves it: a process id no process has
    // (above the kernel's limit of 2^22).
    let stale = dir.join(".hits.npy.tmp-4194999-0");
    std::fs::write(&stale, b"").unwrap();
    let out =
        run(&[&"trace", &"--scene", &scene, &"--rays", &rays, &"--method", &"stack", &"--out", &dir.join("hits.npy")]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stale.exists(), "the killed run's temporary file is still there");
}

#[cfg(unix)]
#[test]
fn a_full_stdout_ends_the_command_with_one_line_not_a_panic() {
    if !Path::new("/dev/full").exists() {
        panic!("this test needs /dev/full (every Linux has it)");
    }
    let teapot = mesh_path("teapot.obj");
    let dir = folder("full");
    let rays = dir.join("rays.npy");
    for args in [
        vec!["--help".to_string()],
        vec![
            "explain".into(),
            teapot.display().to_string(),
            "--width".into(),
            "8".into(),
            "--height".into(),
            "6".into(),
        ],
        vec!["rays".into(), "--scene".into(), teapot.display().to_string(), "--out".into(), rays.display().to_string()],
    ] {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let out = bin().args(&args).stdout(full).output().unwrap();
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_eq!(err.matches("cannot write to stdout").count(), 1, "{args:?}: {err}");
    }
}

#[test]
fn a_folder_given_as_a_scene_is_called_a_folder() {
    let dir = folder("scene-folder");
    let out = run(&[&"rays", &"--scene", &dir, &"--out", &dir.join("rays.npy")]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("it is a folder"), "{}", stderr(&out));
}
