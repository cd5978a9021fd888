//! The command line end to end: `rays` writes a NumPy ray file, `trace` reads it and writes hits
//! that match tracing the same rays through the library; bad input gives an error, not a panic.

mod scratch;

use raytrail::core::method::{Bvh2Method, Method};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::trace::{Trace, TraceOptions};
use raytrail::core::Hit;
use raytrail::cpu::CpuBackend;
use raytrail::Builder;
use raytrail_cli::npy;
use raytrail_conformance::paths::mesh_path;
use scratch::Scratch;
use std::path::PathBuf;
use std::process::Command;
use std::sync::Arc;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raytrail"))
}

#[test]
fn rays_then_trace_matches_the_library() {
    let dir = Scratch::new("cli");
    // The Cornell box ships in the conformance crate: no scenes folder is needed.
    let scene = mesh_path("cornell_box.obj");
    let (rays, hits) = (dir.join("rays.npy"), dir.join("hits.npy"));
    let out = bin()
        .args(["rays", "--scene"])
        .arg(&scene)
        .arg("--out")
        .arg(&rays)
        .args(["--width", "40", "--height", "30"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for method in ["stack", "hash", "hash-resume", "auto"] {
        let out = bin()
            .args(["trace", "--scene"])
            .arg(&scene)
            .arg("--rays")
            .arg(&rays)
            .args(["--method", method, "--out"])
            .arg(&hits)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let got = npy::read_hits(&hits).unwrap();
        let ray_list = npy::read_rays(&rays).unwrap();
        assert_eq!(got.len(), 1200);
        let named = raytrail_conformance::load_mesh_scene(scene.to_str().unwrap()).unwrap();
        let bvh = Builder::Sah.build(&named.scene).unwrap();
        let prepared = PreparedScene::new(&named.scene, bvh, &[Method::Bvh2(Bvh2Method::Stack)]).unwrap();
        let backend = CpuBackend::new();
        let cpu = backend.prepare(Arc::new(prepared)).unwrap();
        let mut expected = vec![Hit::MISS; ray_list.len()];
        backend.trace(&cpu, &ray_list, &TraceOptions::new(Method::Bvh2(Bvh2Method::Stack)), &mut expected).unwrap();
        assert!(got.iter().zip(&expected).all(|(a, b)| a.same_as(b)), "{method}: hits differ from the library's");
        assert!(got.iter().any(Hit::is_hit) && got.iter().any(|h| !h.is_hit()));
    }
}

/// Bad input is an error, not a panic: usage errors exit with status 2, failures while working
/// (a file that does not load) with status 1.
#[test]
fn bad_input_is_an_error_not_a_panic() {
    let dir = Scratch::new("cli");
    let bad = dir.join("bad.npy");
    std::fs::write(&bad, b"not a numpy file").unwrap();
    let cases: Vec<(i32, Vec<String>)> = vec![
        (
            1,
            vec![
                "trace".into(),
                "--scene".into(),
                "builtin".into(),
                "--rays".into(),
                bad.display().to_string(),
                "--out".into(),
                "x.npy".into(),
            ],
        ),
        (
            1,
            vec![
                "trace".into(),
                "--scene".into(),
                "/nonexistent.obj".into(),
                "--rays".into(),
                "r.npy".into(),
                "--out".into(),
                "x".into(),
            ],
        ),
        (2, vec!["trace".into(), "--scene".into(), "builtin".into(), "--method".into(), "nope".into()]),
        (2, vec!["run".into(), "--width".into(), "many".into()]),
        (2, vec!["frobnicate".into()]),
    ];
    for (code, args) in cases {
        let out = bin().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains("error:") && !err.contains("panicked"), "{args:?}: {err}");
    }
}

/// A negative number is read as the value of the flag before it, so the error names that flag
/// (clap alone reads `-5` as an unknown flag).
#[test]
fn a_negative_number_is_an_error_naming_its_flag() {
    for (flag, value) in [("--max-mesh-bytes", "-5"), ("--gpu-warm-up", "-1"), ("--stream-cell", "-0.5")] {
        let sub = if flag == "--max-mesh-bytes" { "rays" } else { "bench" };
        let out = bin().args([sub, "--scene", "builtin", flag, value]).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flag} {value}: {err}");
        assert!(err.contains(flag) && !err.contains("unexpected argument"), "{flag} {value}: {err}");
    }
}

/// `bench --peers embree`: with the `embree` feature, Embree is measured beside raytrail and its
/// occlusion agrees with the stack method's; without it, a usage error says how to get it.
#[test]
fn bench_with_embree_needs_the_feature() {
    let dir = Scratch::new("cli");
    let json = dir.join("embree.json");
    let out = bin()
        .args(["bench", "--scene", "builtin", "--peers", "embree", "--baseline", "embree", "--methods", "stack"])
        .args(["--rays", "primary,shadow", "--width", "32", "--height", "24", "--passes", "1", "--threads", "1"])
        .args(["--no-gpu", "--view", "both", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    if !cfg!(feature = "embree") {
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains("built without the `embree` cargo feature"), "{stderr}");
        return;
    }
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("embree (default quality, rtcCommitScene)"), "{stdout}");
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let scenes = doc["scenes"].as_array().unwrap();
    assert_eq!(scenes.iter().map(|s| s["view"].as_str().unwrap()).collect::<Vec<_>>(), ["outside", "inside"]);
    for scene in scenes {
        for rays in scene["rays"].as_array().unwrap() {
            let a = rays["agreement"].as_array().unwrap().iter().find(|a| a["target"] == "embree").unwrap();
            let (n, close) = (a["rays"].as_f64().unwrap(), a["within_tolerance"].as_f64().unwrap());
            assert!(close >= 0.99 * n, "{} {}: {a}", scene["name"], rays["type"]);
        }
    }
}

/// An OBJ with edges written as 2-vertex faces, a polyline and a point loads by default with one
/// warning line naming the count and the first location; `--strict` makes it today's error.
#[test]
fn short_faces_lines_and_points_warn_by_default_and_fail_under_strict() {
    let dir = Scratch::new("cli");
    let obj = dir.join("edges.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4\nl 1 2 3\np 4\nf 2 4 3\n").unwrap();
    let rays = dir.join("edges_rays.npy");
    let run = |strict: bool| {
        let mut cmd = bin();
        cmd.args(["rays", "--scene", &obj.display().to_string(), "--out", &rays.display().to_string()]);
        if strict {
            cmd.arg("--strict");
        }
        cmd.output().unwrap()
    };
    let lenient = run(false);
    let err = String::from_utf8_lossy(&lenient.stderr);
    assert!(lenient.status.success(), "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(warnings[0].contains('3') && warnings[0].contains("line 6"), "{}", warnings[0]);
    let strict = run(true);
    let err = String::from_utf8_lossy(&strict.stderr);
    assert!(!strict.status.success(), "{err}");
    assert!(err.contains("face has 2 vertices; a face needs at least 3") && !err.contains("panicked"), "{err}");
}

#[test]
fn render_with_auto_draws_what_its_chosen_method_draws() {
    let dir = Scratch::new("cli");
    let run = |method: &str, out: &PathBuf| {
        let o = bin()
            .args([
                "render", "--scene", "builtin", "--mode", "heat", "-W", "48", "-H", "32", "--method", method, "--out",
            ])
            .arg(out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let auto_png = dir.join("auto.png");
    let told = run("auto", &auto_png);
    let chosen = told
        .lines()
        .find_map(|l| l.strip_prefix("auto: "))
        .and_then(|l| l.split_whitespace().next())
        .unwrap_or_else(|| panic!("no choice printed: {told}"))
        .to_string();
    let fixed_png = dir.join("fixed.png");
    run(&chosen, &fixed_png);
    assert_eq!(std::fs::read(&auto_png).unwrap(), std::fs::read(&fixed_png).unwrap(), "auto chose {chosen}");
}

#[test]
fn the_main_job_on_a_scene_the_camera_rays_miss_says_so_and_passes() {
    let dir = Scratch::new("cli");
    // Two degenerate triangles on a line: every camera ray misses, so there are no shadow or
    // diffuse rays to choose a method on (it failed with "auto: invalid rays").
    let scene = dir.join("degenerate.obj");
    std::fs::write(&scene, "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 3 2\n").unwrap();
    let out =
        bin().args(["run", "--no-gpu", "--width", "16", "--height", "12", "--scene"]).arg(&scene).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}\n{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        text.contains("auto: no rays to choose on (the camera rays hit nothing, so there are no shadow rays)"),
        "{text}"
    );
}

/// `rays --scene /dev/stdin --max-mesh-bytes max` with `data` written to its stdin (a pipe).
fn rays_from_stdin(data: Vec<u8>, max: &str) -> std::process::Output {
    use std::io::Write;
    let dir = Scratch::new("cli");
    let mut child = bin()
        .args(["rays", "--scene", "/dev/stdin", "--width", "8", "--height", "6", "--max-mesh-bytes", max, "--out"])
        .arg(dir.join("stdin-rays.npy"))
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    // The reader may stop early (past the limit): a failed write is its answer, not an error.
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&data);
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    out
}

#[test]
fn a_mesh_from_a_pipe_is_read_as_a_stream_with_its_format_from_its_content() {
    use std::io::Write;
    let dir = Scratch::new("cli");
    let teapot = std::fs::read(mesh_path("teapot.obj")).unwrap();
    // OBJ has no magic number: a pipe has no extension, so the content says what it is.
    let out = rays_from_stdin(teapot.clone(), "100000000");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(&teapot).unwrap();
    let out = rays_from_stdin(gz.finish().unwrap(), "100000000");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // A stream says nothing of its size: past --max-mesh-bytes it is an error, not a hang.
    let out = rays_from_stdin(vec![b'#'; 1 << 20], "100000");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("a stream longer than 100000 bytes"), "{err}");
    // A device is no mesh.
    let out = bin().args(["rays", "--scene", "/dev/zero", "--out"]).arg(dir.join("zero.npy")).output().unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("it is a device, not a file or a pipe"));
}

#[test]
fn paths_are_taken_as_the_system_has_them_not_only_as_utf8() {
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    let dir = Scratch::new("cli");
    let named = |bytes: &[u8]| dir.join(OsStr::from_bytes(bytes));
    let (scene, rays, hits, image) =
        (named(b"tea\xffpot.obj"), named(b"rays\xfe.npy"), named(b"hits\xfd.npy"), named(b"image\xfc.png"));
    std::fs::copy(mesh_path("teapot.obj"), &scene).unwrap();
    let ok = |out: std::process::Output| assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    ok(bin()
        .args(["rays", "--width", "8", "--height", "6", "--scene"])
        .arg(&scene)
        .arg("--out")
        .arg(&rays)
        .output()
        .unwrap());
    ok(bin().args(["trace", "--scene"]).arg(&scene).arg("--rays").arg(&rays).arg("--out").arg(&hits).output().unwrap());
    ok(bin()
        .args(["render", "--width", "8", "--height", "6", "--scene"])
        .arg(&scene)
        .arg("--out")
        .arg(&image)
        .output()
        .unwrap());
    assert_eq!(npy::read_hits(&hits).unwrap().len(), 48);
    assert!(image.is_file());
    // An output naming the input is still caught, whatever the bytes of its name.
    let out =
        bin().args(["trace", "--scene"]).arg(&scene).arg("--rays").arg(&rays).arg("--out").arg(&rays).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    // The commands that take comma-separated lists of scenes keep each path's bytes too, and so
    // do their JSON outputs.
    let mut list = std::ffi::OsString::from("builtin, ");
    list.push(&scene);
    let (bench_json, accuracy_json) = (named(b"bench\xfb.json"), named(b"accuracy\xfa.json"));
    let tiny = ["-W", "16", "-H", "12", "--passes", "1", "--rays", "primary", "--methods", "stack"];
    ok(bin()
        .args(["bench", "--peers", "none", "--no-gpu", "--view", "outside"])
        .args(tiny)
        .arg("--scene")
        .arg(&list)
        .arg("--json")
        .arg(&bench_json)
        .output()
        .unwrap());
    // `accuracy --scene` may also be given once per scene.
    ok(bin()
        .args(["accuracy", "--sample", "8", "--scene", "builtin", "--scene"])
        .arg(&scene)
        .args(tiny)
        .arg("--json")
        .arg(&accuracy_json)
        .output()
        .unwrap());
    for json in [&bench_json, &accuracy_json] {
        let text = std::fs::read_to_string(json).unwrap();
        assert!(text.contains("tea\u{fffd}pot"), "both scenes reported: {text:.300}");
    }
}
