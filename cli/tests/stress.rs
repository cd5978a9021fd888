//! `raytrail stress` end to end on the CPU: every case of the numerics stress suite is reported,
//! the run agrees with the exact reference, and the range-edge cases show their refusals.

use std::process::Command;

#[test]
fn stress_reports_every_case_and_agrees() {
    let out = Command::new(env!("CARGO_BIN_EXE_raytrail")).args(["stress", "--no-gpu"]).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    let names = raytrail_conformance::stress::case_names().expect("the cases can be made");
    for name in &names {
        assert!(stdout.lines().any(|l| l.starts_with(name.as_str())), "case '{name}' not reported:\n{stdout}");
    }
    assert!(stdout.contains("stress: every ray agrees"), "{stdout}");
    // Just outside the range, every ray is refused and shown as such, not as a miss.
    let edge = stdout.lines().find(|l| l.starts_with("range edge: origins 1e10 away")).expect("edge case");
    let cols: Vec<&str> = edge.split_whitespace().rev().take(5).collect();
    assert_eq!(cols[0], "0", "no disagreement: {edge}");
    assert_ne!(cols[1], "0", "refusals shown: {edge}");
}
