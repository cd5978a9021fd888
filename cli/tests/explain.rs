//! `raytrail explain` end to end: it analyses the built-in scene (tables, choices per ray type,
//! needs, kernels) as text and JSON, and bad input is an error with the right exit status, never a
//! panic.

mod scratch;

use scratch::Scratch;
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raytrail")).args(args).output().unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn explain_analyses_the_builtin_scene() {
    let dir = Scratch::new("explain");
    let json = dir.join("explain.json");
    let out = run(&["explain", "builtin", "-W", "32", "-H", "24", "--json", json.to_str().unwrap()]);
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{}\n{}", stdout, text(&out.stderr));
    for section in
        ["tables, each built alone:", "method per ray set", "what the chosen methods need:", "what it saves:"]
    {
        assert!(stdout.contains(section), "missing '{section}':\n{stdout}");
    }
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["scene"], "sphereflake");
    assert_eq!(v["parts"].as_array().unwrap().len(), raytrail::core::prepared::Part::ALL.len());
    assert_eq!(v["methods"].as_array().unwrap().len(), raytrail::core::method::Method::ALL.len());
    let choices = v["choices"].as_array().unwrap();
    let kinds: Vec<&str> = choices.iter().map(|c| c["rays"].as_str().unwrap()).collect();
    assert_eq!(kinds, ["primary", "shadow", "soft-shadow", "diffuse", "ao"]);
    let candidates: Vec<&str> = raytrail::analysis::choice::CANDIDATES.iter().map(|m| m.name()).collect();
    for c in choices {
        let chosen = c["chosen"].as_str().unwrap();
        assert!(candidates.contains(&chosen), "{chosen} is not among {candidates:?}");
    }
    // The chosen methods' tables are fewer than every method's, and so are the kernels.
    let saves = &v["saves"];
    assert!(saves["chosen_bytes"].as_u64().unwrap() < saves["all_bytes"].as_u64().unwrap());
    let kernels = saves["kernels"].as_array().unwrap().len();
    assert!((1..=5).contains(&kernels) && (kernels as u64) < saves["all_kernels"].as_u64().unwrap());
    assert_eq!(v["needs"]["disjoint_mask"]["needed"], false);
    assert_eq!(v["needs"]["slack"]["needed"], true);
}

#[test]
fn explain_fails_cleanly_on_bad_input() {
    let dir = Scratch::new("explain");
    let cases: [(&[&str], i32); 5] = [
        (&["explain", "no/such/scene.obj"], 1),
        (&["explain", "builtin", "--rays", "no/such/rays.npy"], 1),
        (&["explain", "builtin", "--any"], 2),
        (&["explain", "builtin", "--view", "sideways"], 2),
        (&["explain"], 2),
    ];
    for (args, code) in cases {
        let out = run(args);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    // A file that is not a ray file, and a scene file that is not a mesh.
    let bad = dir.join("bad.npy");
    std::fs::write(&bad, b"not numpy").unwrap();
    for args in [vec!["explain", "builtin", "--rays", bad.to_str().unwrap()], vec!["explain", bad.to_str().unwrap()]] {
        let out = run(&args);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.starts_with("error: ") || stderr.contains("\nerror: "), "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}

#[test]
fn explain_takes_a_ray_file() {
    let dir = Scratch::new("explain");
    let (rays, json) = (dir.join("rays.npy"), dir.join("rays.json"));
    let out = run(&["rays", "--scene", "builtin", "--out", rays.to_str().unwrap(), "-W", "24", "-H", "16"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out = run(&["explain", "builtin", "--rays", rays.to_str().unwrap(), "--json", json.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let choices = v["choices"].as_array().unwrap();
    assert_eq!(choices.len(), 1);
    assert_eq!(choices[0]["count"], 384);
    assert_eq!(choices[0]["query"], "closest");
    assert_eq!(choices[0]["refused"], 0);
}
