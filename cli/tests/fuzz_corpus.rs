//! Every fuzz target's corpus (`fuzz/corpus/<target>/`, the seeds and every input a campaign kept
//! or crashed on) replayed through the target's body (`raytrail_cli::fuzz`) on the stable
//! toolchain: a crash the fuzzer found stays fixed. Every target must have a corpus.

use raytrail_cli::fuzz;
use std::path::Path;

/// A target's body.
type Body = Box<dyn Fn(&[u8])>;

/// The targets of `fuzz/Cargo.toml` and their bodies.
fn body(target: &str) -> Option<Body> {
    if let Some(format) = target.strip_prefix("mesh_") {
        let name = match format {
            "obj" => "x.obj",
            "ply" => "x.ply",
            "off" => "x.off",
            "stl" => "x.stl",
            "gltf" => "x.gltf",
            "glb" => "x.glb",
            "gzip" => "x.obj.gz",
            "sniffed" => "x",
            _ => return None,
        };
        assert!(fuzz::MESH_NAMES.contains(&name), "{name}");
        return Some(Box::new(move |data| fuzz::mesh_file(name, data)));
    }
    match target {
        "npy_rays" => Some(Box::new(fuzz::npy_rays)),
        "trace" => Some(Box::new(fuzz::trace)),
        _ => None,
    }
}

#[test]
fn every_corpus_input_replays_without_a_finding() {
    let fuzz_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz");
    let manifest = std::fs::read_to_string(fuzz_dir.join("Cargo.toml")).unwrap();
    let targets: Vec<&str> = manifest
        .lines()
        .filter_map(|l| l.strip_prefix("name = \""))
        .filter_map(|l| l.strip_suffix('"'))
        .filter(|n| *n != "raytrail-fuzz")
        .collect();
    assert_eq!(targets.len(), 10, "{targets:?}");
    let mut replayed = 0;
    for target in targets {
        let run = body(target).unwrap_or_else(|| panic!("no body for fuzz target {target}"));
        let dir = fuzz_dir.join("corpus").join(target);
        let inputs: Vec<_> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{target}: no corpus at {}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .collect();
        assert!(!inputs.is_empty(), "{target}: an empty corpus replays nothing");
        for input in inputs {
            let data = std::fs::read(&input).unwrap();
            eprintln!("{target}: {}", input.display());
            run(&data);
            replayed += 1;
        }
    }
    eprintln!("{replayed} corpus inputs replayed");
}
