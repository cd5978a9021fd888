//! One test per command-line problem the "ecosystem command line" issue found: each failed before
//! the command line moved to clap, atomic writes, limits and `render`.

mod scratch;

use raytrail_cli::npy;
use raytrail_conformance::rays::{primary, Camera};
use scratch::Scratch;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raytrail"))
}

/// A fresh folder of the test's own, removed when it passes.
fn folder(test: &str) -> Scratch {
    Scratch::new(&format!("cli-found-{test}"))
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// Asserts a usage error: status 2, an error line, no panic.
fn assert_usage_error(out: &Output, what: &str) -> String {
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{what}: {err}");
    assert!(err.contains("error:") && !err.contains("panicked"), "{what}: {err}");
    err
}

/// `trace --help`, `bench --help`, `rays --help` (and `render --help`) print their own help.
#[test]
fn subcommand_help_is_the_subcommand_s() {
    for (cmd, flag) in [("trace", "--rays <RAYS.npy>"), ("bench", "--peers"), ("rays", "--order"), ("render", "--mode")]
    {
        let out = run(&[cmd, "--help"]);
        let help = text(&out.stdout);
        assert!(out.status.success(), "{cmd}: {}", text(&out.stderr));
        assert!(help.contains(&format!("Usage: raytrail {cmd}")) && help.contains(flag), "{cmd}: {help}");
        // `-h` is the short form.
        assert!(text(&run(&[cmd, "-h"]).stdout).contains(&format!("Usage: raytrail {cmd}")));
    }
}

/// `--version` prints the version instead of "needs a value".
#[test]
fn version_prints_the_version() {
    let out = run(&["--version"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(text(&out.stdout), format!("raytrail {}\n", env!("CARGO_PKG_VERSION")));
}

/// `--scene=FILE` (any `--flag=value`) is understood.
#[test]
fn flag_equals_value_is_understood() {
    let dir = folder("equals");
    let rays = dir.join("rays.npy");
    let out = run(&["rays", "--scene=builtin", &format!("--out={}", p(&rays)), "--width=4", "--height=3"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(npy::read_rays(&rays).unwrap().len(), 12);
}

/// A repeated flag is an error, not "the last one wins".
#[test]
fn repeated_flags_are_errors() {
    let dir = folder("repeated");
    let out = p(&dir.join("rays.npy")).to_string();
    for args in [
        vec!["rays", "--scene", "builtin", "--out", &out, "--width", "4", "--width", "5"],
        vec!["rays", "--scene", "builtin", "--out", &out, "--strict", "--strict"],
    ] {
        let err = assert_usage_error(&run(&args), "repeated");
        assert!(err.contains("cannot be used multiple times"), "{err}");
    }
    assert!(!dir.join("rays.npy").exists());
}

/// A trailing unknown flag is reported as unknown, not as "needs a value".
#[test]
fn a_trailing_unknown_flag_is_unknown() {
    let err = assert_usage_error(&run(&["rays", "--scene", "builtin", "--out", "x.npy", "--bogus"]), "--bogus");
    assert!(err.contains("unexpected argument '--bogus'") && !err.contains("needs a value"), "{err}");
}

/// `--method` is optional with the default `auto`, and the help says so.
#[test]
fn method_is_optional_with_its_default_shown() {
    let help = text(&run(&["trace", "--help"]).stdout);
    let usage = help.lines().find(|l| l.starts_with("Usage:")).unwrap();
    assert!(!usage.contains("--method"), "{usage}");
    let after = &help[help.find("--method").unwrap()..];
    assert!(after[..after.find("--out").unwrap()].contains("[default: auto]"), "{help}");
}

/// Defaults are shown in the help.
#[test]
fn defaults_are_shown() {
    let help = text(&run(&["run", "--help"]).stdout);
    for d in ["[default: builtin]", "[default: best]", "[default: 320]", "[default: 240]", "[default: 5]"] {
        assert!(help.contains(d), "run: {d}: {help}");
    }
    let help = text(&run(&["bench", "--help"]).stdout);
    for d in ["[default: 512]", "[default: auto]", "[default: 4]"] {
        assert!(help.contains(d), "bench: {d}: {help}");
    }
}

/// Output into a closed pipe (`raytrail --help | head -3`) ends the process quietly: no panic.
#[test]
fn a_closed_pipe_is_no_panic() {
    let dir = folder("pipe");
    let rays = dir.join("rays.npy");
    for args in [vec!["--help"], vec!["rays", "--scene", "builtin", "--out", p(&rays), "--width", "8", "--height", "8"]]
    {
        let mut child = bin().args(&args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let err = text(&out.stderr);
        assert!(!err.contains("panicked") && out.status.code() != Some(101), "{args:?}: {err}");
    }
}

/// Usage errors exit with status 2, failures while working with status 1.
#[test]
fn usage_errors_and_failures_have_their_own_status() {
    assert_usage_error(&run(&["run", "--width", "many"]), "--width many");
    assert_usage_error(&run(&["frobnicate"]), "frobnicate");
    assert_usage_error(&run(&["bench", "--passes", "0"]), "--passes 0");
    let dir = folder("status");
    let bad = dir.join("bad.npy");
    std::fs::write(&bad, b"not a numpy file").unwrap();
    let hits = dir.join("hits.npy");
    for args in [
        vec!["rays", "--scene", "/nonexistent.obj", "--out", p(&dir.join("r.npy"))],
        vec!["trace", "--scene", "builtin", "--rays", p(&bad), "--out", p(&hits)],
    ] {
        let out = run(&args);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("error:") && !err.contains("panicked"), "{args:?}: {err}");
    }
}

/// `trace` reports a missing `--rays` before it loads the scene.
#[test]
fn trace_wants_its_rays_before_loading() {
    let err = assert_usage_error(&run(&["trace", "--scene", "/nonexistent.obj", "--out", "x.npy"]), "no --rays");
    assert!(err.contains("--rays") && !err.contains("nonexistent") && !err.contains("loading"), "{err}");
}

/// Output folders are checked before any loading, building or tracing.
#[test]
fn output_folders_are_checked_before_any_work() {
    let dir = folder("outdir");
    let rays = dir.join("rays.npy");
    assert!(run(&["rays", "--scene", "builtin", "--out", p(&rays), "--width", "4", "--height", "4"]).status.success());
    let missing = dir.join("no/such/folder/out");
    let missing = p(&missing);
    for (flag, args) in [
        ("--out", vec!["trace", "--scene", "builtin", "--rays", p(&rays), "--out", missing]),
        (
            "--prim-map",
            vec!["trace", "--scene", "builtin", "--rays", p(&rays), "--out", "h.npy", "--prim-map", missing],
        ),
        ("--out", vec!["rays", "--scene", "builtin", "--out", missing]),
        ("--out", vec!["render", "--scene", "builtin", "--out", missing]),
        ("--json", vec!["bench", "--json", missing]),
        ("--plot", vec!["bench", "--plot", missing]),
    ] {
        let err = assert_usage_error(&run(&args), flag);
        assert!(err.contains(flag) && err.contains("does not exist"), "{args:?}: {err}");
        assert!(!err.contains("loading") && !err.contains("building"), "{args:?}: work before the check: {err}");
    }
    assert!(!Path::new("h.npy").exists());
}

/// A write that fails part-way (here: beyond the file size limit) leaves the previous file as it
/// was, and no temporary file.
#[cfg(unix)]
#[test]
fn a_failed_write_keeps_the_previous_file() {
    let dir = folder("atomic");
    let rays = dir.join("rays.npy");
    std::fs::write(&rays, b"the previous good file").unwrap();
    let out = Command::new("sh")
        .arg("-c")
        .arg("ulimit -f 1; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_raytrail"))
        .args(["rays", "--scene", "builtin", "--width", "64", "--height", "64", "--out", p(&rays)])
        .output()
        .unwrap();
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("error:") && !err.contains("panicked"), "{err}");
    assert_eq!(std::fs::read(&rays).unwrap(), b"the previous good file");
    let names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, ["rays.npy"]);
}

/// `rays --width 65536 --height 65536` (and a render as large) is a clear error within a second,
/// not "memory allocation failed".
#[test]
fn huge_images_are_errors_not_aborts() {
    let dir = folder("huge");
    for (flag, args) in [
        ("--max-rays", vec!["rays", "--scene", "builtin", "--width", "65536", "--height", "65536"]),
        ("--max-pixels", vec!["render", "--scene", "builtin", "--width", "65536", "--height", "65536"]),
        ("--max-rays", vec!["run", "--width", "65536", "--height", "65536"]),
    ] {
        let out_path = dir.join("out");
        let start = Instant::now();
        let mut args = args.clone();
        if args[0] != "run" {
            args.extend(["--out", p(&out_path)]);
        }
        let err = assert_usage_error(&run(&args), flag);
        assert!(start.elapsed() < Duration::from_secs(1), "{args:?} took {:?}", start.elapsed());
        assert!(err.contains(flag) && err.contains("4294967296"), "{err}");
    }
}

/// `rays --order raster` writes ray i through pixel (i % width, i / width); the default stays
/// Morton order, as documented in `rays --help`.
#[test]
fn rays_in_raster_or_morton_order() {
    let dir = folder("order");
    let (raster, morton) = (dir.join("raster.npy"), dir.join("morton.npy"));
    let (w, h) = (7u32, 5u32);
    let size = ["--width", "7", "--height", "5"];
    assert!(run(&[&["rays", "--scene", "builtin", "--order", "raster", "--out", p(&raster)][..], &size].concat())
        .status
        .success());
    assert!(run(&[&["rays", "--scene", "builtin", "--out", p(&morton)][..], &size].concat()).status.success());
    let scene = raytrail_conformance::suite::generated_scene("sphereflake").scene;
    let camera = Camera::framing(scene.bounds());
    let got = npy::read_rays(&raster).unwrap();
    for (i, ray) in got.iter().enumerate() {
        let (x, y) = (i as u32 % w, i as u32 / w);
        assert_eq!(*ray, camera.ray(x as f32 + 0.5, y as f32 + 0.5, w, h), "ray {i}");
    }
    assert_eq!(npy::read_rays(&morton).unwrap(), primary(&scene, w, h));
    let help = text(&run(&["rays", "--help"]).stdout);
    assert!(help.contains("(i % width, i / width)") && help.contains("Morton"), "{help}");
}

/// Decodes a PNG: width, height and RGB bytes.
fn decode_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

/// `raytrail render` on the built-in scene writes a PNG of the asked size that is not uniform, in
/// every mode.
#[test]
fn render_writes_a_png_of_the_scene() {
    let dir = folder("render");
    for (mode, method) in
        [("normals", "stack"), ("ao", "hash"), ("heat", "hash"), ("heat", "kd-restart"), ("backtracks", "hash")]
    {
        let image = dir.join(format!("{mode}-{method}.png"));
        let out = run(&[
            "render",
            "--scene",
            "builtin",
            "--mode",
            mode,
            "--method",
            method,
            "--width",
            "48",
            "--height",
            "32",
            "--ao-rays",
            "4",
            "--out",
            p(&image),
        ]);
        assert!(out.status.success(), "{mode}: {}", text(&out.stderr));
        let (w, h, rgb) = decode_png(&image);
        assert_eq!((w, h, rgb.len()), (48, 32, 48 * 32 * 3), "{mode}");
        let first = &rgb[..3];
        let distinct = rgb.chunks_exact(3).filter(|px| *px != first).count();
        assert!(distinct > 48, "{mode} {method}: the image is (almost) uniform");
    }
}

/// A PLY header of 100,000 properties is rejected within a second (it took 33 s: the duplicate
/// property check was quadratic).
#[test]
fn a_ply_header_of_many_properties_is_rejected_fast() {
    let dir = folder("ply");
    let ply = dir.join("many.ply");
    let mut header = String::from("ply\nformat ascii 1.0\nelement vertex 1\n");
    for i in 0..100_000 {
        header.push_str(&format!("property float p{i}\n"));
    }
    header.push_str("end_header\n");
    std::fs::write(&ply, header).unwrap();
    let start = Instant::now();
    let out = run(&["rays", "--scene", p(&ply), "--out", p(&dir.join("rays.npy"))]);
    let err = text(&out.stderr);
    assert!(start.elapsed() < Duration::from_secs(1), "took {:?}", start.elapsed());
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("vertex element has no `x` property"), "{err}");
}

/// `--builder ploc` on 30,000 copies of one triangle finishes within a second (it took 22 s); on
/// triangles collapsed to one point it says that the SAH builder builds the tree instead.
#[test]
fn ploc_on_coincident_triangles_is_fast() {
    let dir = folder("ploc");
    let rays = dir.join("rays.npy");
    let hits = dir.join("hits.npy");
    for (name, vertex, warns) in [("copies", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", false), ("points", "v 1 1 1\n", true)] {
        let obj = dir.join(format!("{name}.obj"));
        let faces = if warns { "f 1 1 1\n" } else { "f 1 2 3\n" };
        std::fs::write(&obj, format!("{vertex}{}", faces.repeat(30_000))).unwrap();
        assert!(run(&["rays", "--scene", p(&obj), "--out", p(&rays), "--width", "8", "--height", "8"])
            .status
            .success());
        let start = Instant::now();
        let out = run(&[
            "trace",
            "--scene",
            p(&obj),
            "--rays",
            p(&rays),
            "--out",
            p(&hits),
            "--builder",
            "ploc",
            "-m",
            "stack",
        ]);
        let err = text(&out.stderr);
        assert!(out.status.success(), "{name}: {err}");
        assert!(start.elapsed() < Duration::from_secs(2), "{name}: took {:?}", start.elapsed());
        assert_eq!(err.contains("the SAH builder builds this tree instead"), warns, "{name}: {err}");
    }
}

/// A small gzip that inflates far beyond the limit on decompressed meshes is an error within a
/// second, not an allocation abort; the limit is a flag.
#[test]
fn a_gzip_bomb_is_an_error_not_an_abort() {
    use std::io::Write;
    let dir = folder("gzip_bomb");
    let bomb = dir.join("bomb.obj.gz");
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    let zeros = vec![b'#'; 1 << 20];
    for _ in 0..64 {
        gz.write_all(&zeros).unwrap();
    }
    std::fs::write(&bomb, gz.finish().unwrap()).unwrap();
    let start = std::time::Instant::now();
    let out = run(&["rays", "--scene", p(&bomb), "--out", p(&dir.join("r.npy")), "--max-mesh-bytes", "1000000"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("inflates to more than 1000000 bytes") && !err.contains("panicked"), "{err}");
    assert!(start.elapsed().as_secs_f64() < 1.0, "took {:?}", start.elapsed());
}
