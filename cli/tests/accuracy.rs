//! `raytrail accuracy` end to end on the built-in scene with a tiny sample: the table, the JSON
//! and the plot are written, the default methods make no error, and bad flags fail cleanly.

mod scratch;

use scratch::Scratch;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_raytrail"))
}

#[test]
fn a_tiny_run_writes_table_json_and_plot() {
    let dir = Scratch::new("cli-accuracy");
    let (json, plot) = (dir.join("acc.json"), dir.join("acc.svg"));
    let out = bin()
        .args(["accuracy", "--scene", "builtin", "-W", "16", "-H", "12", "--sample", "40", "--passes", "1"])
        .args(["--methods", "hash,kd-stack,bvh4", "--rays", "primary,shadow,diffuse,ao", "--ao-rays", "1"])
        .arg("--json")
        .arg(&json)
        .arg("--plot")
        .arg(&plot)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("judged against the exact reference") && stdout.contains("(d)"), "{stdout}");
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["default_method"], "hash");
    let scenes = v["scenes"].as_array().unwrap();
    assert_eq!(scenes.len(), 1, "the sphereflake has no inside view");
    let sets = scenes[0]["rays"].as_array().unwrap();
    assert_eq!(
        sets.iter().map(|s| s["kind"].as_str().unwrap()).collect::<Vec<_>>(),
        ["primary", "shadow", "diffuse", "ao"]
    );
    for set in sets {
        let rows = set["rows"].as_array().unwrap();
        assert_eq!(rows.len(), 6);
        let sampled = set["sampled"].as_u64().unwrap();
        assert!(sampled > 0 && sampled <= 40);
        assert!(rows.iter().any(|r| r["pareto"] == true));
        assert_eq!(rows.iter().filter(|r| r["default"] == true).count(), 1);
        for r in rows {
            assert_eq!(r["rays"].as_u64(), Some(sampled));
            assert!(r["mrays_per_s"].as_f64().unwrap() > 0.0);
            let judged = ["exact", "near", "refused", "false_misses", "false_hits", "wrong_prims", "bad_t"]
                .map(|k| r[k].as_u64().unwrap())
                .iter()
                .sum::<u64>();
            assert_eq!(judged, sampled, "{r}");
            if r["test"] == "watertight" {
                assert_eq!(r["error_rate"].as_f64(), Some(0.0), "{r}");
            }
        }
    }
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("hash, default"));
}

#[test]
fn bad_flags_fail_cleanly() {
    let run = |args: &[&str]| bin().arg("accuracy").args(args).output().unwrap();
    for (args, code, says) in [
        (&["--rays", "sideways"][..], 2, "unknown ray type 'sideways'"),
        (&["--methods", "teleport"], 2, "unknown method 'teleport'"),
        (&["--sample", "0"], 2, "--sample"),
        (&["--tests", "exactish"], 2, "exactish"),
        (&["--scene", "no/such/scene.obj"], 1, "no such file"),
        (&["--json", "/no/such/folder/a.json"], 2, "does not exist"),
    ] {
        let out = run(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}
