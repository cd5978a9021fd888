//! Runs the Cortex-M4F build under `qemu-system-arm -M mps2-an386` and requires its report to
//! equal the host's line for line (every method's hits, counters and digest, and the grid digest);
//! then shows that one changed table entry is caught: a build with one baked word replaced
//! (`RAYTRAIL_EMBEDDED_CORRUPT`) must report differently and fail its self-test.
//!
//! Needs `qemu-system-arm` and the `thumbv7em-none-eabihf` target. Without qemu the test says so
//! loudly and passes, unless `RAYTRAIL_REQUIRE_QEMU` is set (CI sets it), in which case it fails.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const QEMU: &str = "qemu-system-arm";
const TARGET: &str = "thumbv7em-none-eabihf";
/// The root node's first word (its left child's lower x) set to +inf: the left child's box is
/// empty, so every method on the uncle layout loses half the tree.
const CORRUPTION: &str = "uncle_nodes.bin:0=0x7f800000";
/// Far longer than a run takes (well under a second).
const QEMU_TIMEOUT: Duration = Duration::from_secs(120);

fn qemu_available() -> bool {
    Command::new(QEMU).arg("--version").stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok_and(|s| s.success())
}

/// Builds the device binary (release) with `corrupt` as `RAYTRAIL_EMBEDDED_CORRUPT` and copies
/// it to `name` in the test's scratch folder, so a later build cannot change it under the run.
fn build(corrupt: Option<&str>, name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    // A target folder of its own: the outer `cargo test` holds the lock on the usual one.
    let target_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("embedded-qemu");
    let mut cmd = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    cmd.current_dir(&root)
        .args(["build", "--release", "-p", "raytrail-embedded-qemu", "--target", TARGET])
        .env("CARGO_TARGET_DIR", &target_dir)
        .env_remove("RAYTRAIL_EMBEDDED_CORRUPT");
    if let Some(c) = corrupt {
        cmd.env("RAYTRAIL_EMBEDDED_CORRUPT", c);
    }
    let status = cmd.status().expect("run cargo");
    assert!(status.success(), "building the Cortex-M4F binary failed (is the {TARGET} target installed?)");
    let elf = target_dir.join(TARGET).join("release/raytrail-embedded-qemu");
    let copy = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::copy(&elf, &copy).expect("copy the binary");
    copy
}

/// Runs `elf` under qemu (instruction counting on: `-icount shift=0`); returns its exit success
/// and what it printed.
fn run(elf: &Path) -> (bool, String) {
    let mut child = Command::new(QEMU)
        .args(["-M", "mps2-an386", "-cpu", "cortex-m4", "-display", "none", "-serial", "none", "-monitor", "none"])
        .args(["-semihosting-config", "enable=on,target=native", "-icount", "shift=0", "-kernel"])
        .arg(elf)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start qemu");
    let start = Instant::now();
    while child.try_wait().expect("poll qemu").is_none() {
        if start.elapsed() > QEMU_TIMEOUT {
            let _ = child.kill();
            panic!("qemu ran longer than {QEMU_TIMEOUT:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("qemu output");
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    (out.status.success(), text)
}

/// The report's lines: one per method and the grid digest.
fn report_lines(text: &str) -> Vec<&str> {
    text.lines().filter(|l| l.starts_with("method ") || l.starts_with("grid digest ")).collect()
}

#[test]
fn the_cortex_m4f_build_reports_what_the_host_computes_and_catches_a_changed_entry() {
    if !qemu_available() {
        let why = format!("{QEMU} is not installed (Debian: apt-get install qemu-system-arm)");
        if std::env::var_os("RAYTRAIL_REQUIRE_QEMU").is_some() {
            panic!("RAYTRAIL_REQUIRE_QEMU is set but {why}");
        }
        // Past the harness's output capture, so a plain `cargo test` shows why.
        let _ = writeln!(
            std::io::stderr(),
            "\n*** SKIPPED: the Cortex-M4F run under qemu did not happen: {why} (set RAYTRAIL_REQUIRE_QEMU=1 to make this a failure). ***\n"
        );
        return;
    }
    let host = raytrail_embedded_example::grid_report().expect("the host's tables validate").to_string();
    let host_lines: Vec<&str> = host.lines().collect();
    assert_eq!(host_lines.len(), raytrail_embedded_example::METHODS.len() + 1);

    // The corrupted build first, so the scratch target folder ends up with the intact one.
    let bad = build(Some(CORRUPTION), "raytrail-embedded-qemu-corrupt.elf");
    let good = build(None, "raytrail-embedded-qemu.elf");

    let (ok, text) = run(&good);
    println!("{text}");
    assert!(ok, "the device's self-test failed or it did not exit cleanly:\n{text}");
    assert_eq!(report_lines(&text), host_lines, "the device's report differs from the host's");
    let costs: Vec<&str> = text.lines().filter(|l| l.starts_with("cost ")).collect();
    assert_eq!(costs.len(), raytrail_embedded_example::METHODS.len() + 1, "{text}");
    // 40 under `-icount shift=0` at 25 MHz; the loop's 50,000 ticks are counted whole, so where
    // its start falls between two ticks (which moves with the code's layout) may add one: 39.999.
    let per_tick: f64 = text
        .lines()
        .find_map(|l| l.strip_prefix("calibration ")?.strip_suffix(" instructions per SysTick tick")?.parse().ok())
        .unwrap_or_else(|| panic!("no calibration line: {text}"));
    assert!((per_tick - 40.0).abs() <= 0.001, "icount calibration {per_tick}: {text}");

    let (bad_ok, bad_text) = run(&bad);
    let bad_lines = report_lines(&bad_text);
    let differing = bad_lines.iter().zip(&host_lines).filter(|(a, b)| a != b).count();
    println!("with {CORRUPTION}: {differing} of {} report lines differ from the host's", host_lines.len());
    assert!(differing > 0 && bad_lines.len() == host_lines.len(), "a changed table entry went unnoticed:\n{bad_text}");
    assert!(!bad_ok, "the corrupted build's self-test passed:\n{bad_text}");
}
