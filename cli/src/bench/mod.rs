//! `raytrail bench`: raytrail's methods against peer libraries (obvhs's BVH2 and CWBVH, the `bvh`
//! crate) on the same rays, in the same process, on the same thread pools.
//!
//! Per scene: build raytrail's tree, layouts and tables and each peer's own tree; make primary,
//! shadow, diffuse and ambient-occlusion rays once (the secondary rays from the stack method's
//! primary hits); time every target at each thread count ([`measure`]); compare every target's
//! hits with the stack method's ([`agreement`]). Then print tables ([`table`]) and optionally
//! write JSON ([`json`]) and an SVG plot ([`plot`]).

mod agreement;
mod json;
mod measure;
mod options;
mod peers;
mod plot;
mod rays;
mod report;
mod table;
mod target;
mod target_gpu;

use crate::progress::{timed, Progress};
use options::Options;
use raytrail::core::method::{Bvh2Method, Method, Query};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::trace::Trace;
use raytrail::core::Hit;
use raytrail::cpu::CpuScene;
use raytrail::gpu::WgpuBackend;
use raytrail::load_scene;
use report::{BenchReport, Built, SceneReport};
use std::sync::Arc;
use target::{BenchTarget, RaytrailCpu, Targets};
use target_gpu::RaytrailGpu;

/// Runs `raytrail bench` with the arguments after the subcommand.
pub fn main(args: &[String]) -> Result<i32, String> {
    let opts = Options::parse(args)?;
    check_baseline(&opts)?;
    for path in opts.json.iter().chain(&opts.plot) {
        let dir = std::path::Path::new(path).parent().filter(|d| !d.as_os_str().is_empty());
        if dir.is_some_and(|d| !d.is_dir()) {
            return Err(format!("cannot write {path}: its folder does not exist"));
        }
    }
    let pools = opts
        .threads
        .iter()
        .map(|&n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map(|p| (n, p))
                .map_err(|e| format!("cannot start a pool of {n} threads: {e}"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut scenes = Vec::new();
    for path in &opts.scenes {
        let s = bench_scene(path, &opts, &pools)?;
        table::print_scene(&s, &opts.baseline, opts.passes);
        scenes.push(s);
    }
    let report = BenchReport {
        command: std::iter::once("raytrail bench".to_string())
            .chain(args.iter().cloned())
            .collect::<Vec<_>>()
            .join(" "),
        baseline: opts.baseline.clone(),
        passes: opts.passes,
        threads: opts.threads.clone(),
        scenes,
    };
    if let Some(path) = &opts.json {
        std::fs::write(path, json::to_json(&report)).map_err(|e| format!("cannot write {path}: {e}"))?;
        eprintln!("wrote {path}");
    }
    if let Some(path) = &opts.plot {
        std::fs::write(path, plot::to_svg(&report)).map_err(|e| format!("cannot write {path}: {e}"))?;
        eprintln!("wrote {path}");
    }
    Ok(0)
}

/// Fails early when `--baseline` names no target of this run.
fn check_baseline(opts: &Options) -> Result<(), String> {
    let mut names: Vec<String> = opts.methods.iter().map(|m| m.name().to_string()).collect();
    for p in &opts.peers {
        names.push(p.clone());
        names.push(format!("{p}+wt"));
    }
    if names.contains(&opts.baseline) {
        Ok(())
    } else {
        Err(format!("--baseline: '{}' is not measured in this run (measured: {})", opts.baseline, names.join(", ")))
    }
}

/// Loads, builds, makes rays and measures every target on one scene.
fn bench_scene(path: &str, opts: &Options, pools: &[(usize, rayon::ThreadPool)]) -> Result<SceneReport, String> {
    let (named, _) = timed(&format!("loading {path}"), || load_scene(path));
    let named = named?;
    let scene = &named.scene;
    let largest = &pools.last().ok_or("no thread pool")?.1;

    let (bvh, tree_s) = timed(
        &format!("building raytrail's BVH2 ({}, {} triangles)", opts.builder.name(), scene.triangles().len()),
        || largest.install(|| opts.builder.build(scene)),
    );
    let bvh = bvh.map_err(|e| format!("{}: {e}", named.name))?;
    // The stack method always takes part: it makes the secondary rays and the reference hits.
    let mut methods = opts.methods.clone();
    if !methods.contains(&Method::Bvh2(Bvh2Method::Stack)) {
        methods.push(Method::Bvh2(Bvh2Method::Stack));
    }
    let (prepared, _) = timed("deriving raytrail's layouts, hash tables and kd-tree", || {
        largest.install(|| PreparedScene::new(scene, bvh, &methods))
    });
    let prepared = Arc::new(prepared.map_err(|e| format!("{}: {e}", named.name))?);
    let mut builds = raytrail_builds(opts, tree_s, &prepared);
    let cpu = CpuScene(prepared);

    let stack = RaytrailCpu::new(Method::Bvh2(Bvh2Method::Stack), cpu.clone());
    let primary = rays::primary_rays(scene, opts.width, opts.height);
    let mut primary_hits = vec![Hit::MISS; primary.len()];
    stack.trace(largest, &primary, Query::Closest, &mut primary_hits)?;
    let batches = rays::batches(&opts.rays, scene, &primary, &primary_hits, opts.ao_rays);
    let mut references = Vec::with_capacity(batches.len());
    for b in &batches {
        let mut hits = vec![Hit::MISS; b.rays.len()];
        stack.trace(largest, &b.rays, b.kind.query(), &mut hits)?;
        references.push(hits);
    }

    let mut targets: Targets =
        opts.methods.iter().map(|&m| Box::new(RaytrailCpu::new(m, cpu.clone())) as Box<dyn BenchTarget>).collect();
    targets.extend(gpu_targets(opts, &cpu)?);
    let (built, _) = timed("building the peers' trees", || peers::build(&opts.peers, scene, largest));
    let (peer_targets, peer_builds) = built?;
    targets.extend(peer_targets);
    builds.extend(peer_builds);

    let plan = measure::Plan {
        targets: &targets,
        pools,
        passes: opts.passes,
        baseline: &opts.baseline,
        triangles: scene.triangles(),
    };
    let mut progress = Progress::new(&format!("bench {}", named.name), plan.steps_per_batch() * batches.len());
    let mut reports = Vec::with_capacity(batches.len());
    for (b, reference) in batches.iter().zip(&references) {
        reports.push(plan.run(b, reference, &mut progress)?);
    }
    progress.finish();
    Ok(SceneReport {
        name: named.name.clone(),
        triangles: scene.triangles().len(),
        width: opts.width,
        height: opts.height,
        builds,
        rays: reports,
    })
}

/// raytrail's build steps and the memory of each part it derived.
fn raytrail_builds(opts: &Options, tree_s: f64, p: &PreparedScene) -> Vec<Built> {
    let mut out =
        vec![Built { what: format!("raytrail BVH2 ({})", opts.builder.name()), seconds: tree_s, bytes: vec![] }];
    let mut layout_bytes = Vec::new();
    for (name, layout) in [("uncle", &p.uncles), ("parent/sibling", &p.parents)] {
        if let Some(l) = layout {
            layout_bytes.push((format!("{name} layout nodes"), std::mem::size_of_val(l.nodes.as_slice())));
            layout_bytes.push((format!("{name} layout leaf triangles"), std::mem::size_of_val(l.leaves.as_slice())));
        }
    }
    out.push(Built { what: "raytrail layouts".to_string(), seconds: p.timings.layouts, bytes: layout_bytes });
    for (what, hash, secs) in [
        ("raytrail hash tables (backtracking targets)", &p.hash, p.timings.hash),
        ("raytrail hash tables (every node)", &p.full_hash, p.timings.full_hash),
    ] {
        if let Some(h) = hash {
            out.push(Built {
                what: what.to_string(),
                seconds: secs,
                bytes: vec![("tables".to_string(), h.stats.bytes)],
            });
        }
    }
    if let Some(kd) = &p.kd {
        out.push(Built {
            what: "raytrail kd-tree (SAH)".to_string(),
            seconds: p.timings.kd,
            bytes: vec![
                ("nodes and references".to_string(), kd.tree.bytes()),
                ("triangles".to_string(), std::mem::size_of_val(kd.triangles.as_slice())),
            ],
        });
    }
    out
}

/// raytrail's methods on the GPU, when wgpu finds an adapter (and `--no-gpu` is not given);
/// otherwise none, after one line saying why.
fn gpu_targets(opts: &Options, cpu: &CpuScene) -> Result<Targets, String> {
    if opts.no_gpu {
        return Ok(Vec::new());
    }
    let backend = match WgpuBackend::new() {
        Ok(b) => Arc::new(b),
        Err(e) => {
            println!("  GPU: skipped ({e})");
            return Ok(Vec::new());
        }
    };
    let timer = if backend.has_gpu_timer() { "GPU timestamps" } else { "the wall clock, transfers included" };
    println!("  GPU: {}, timed by {timer}", backend.adapter());
    let scene = Arc::new(backend.prepare(cpu.0.clone()).map_err(|e| e.to_string())?);
    Ok(opts
        .methods
        .iter()
        .map(|&m| Box::new(RaytrailGpu::new(m, backend.clone(), scene.clone())) as Box<dyn BenchTarget>)
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tiny_run_measures_every_target_and_agrees() {
        let args: Vec<String> =
            "--width 24 --height 16 --passes 1 --threads 1 --methods stack,hash,kd-stack --ao-rays 2 --builder ploc --no-gpu"
                .split_whitespace()
                .map(str::to_string)
                .collect();
        let opts = Options::parse(&args).unwrap();
        let pools = vec![(1, rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap())];
        let s = bench_scene("builtin", &opts, &pools).unwrap();
        assert_eq!(s.rays.len(), 4);
        assert!(s.builds.iter().any(|b| b.what.starts_with("obvhs-cwbvh")));
        for r in &s.rays {
            // 3 methods, 3 peers with 2 variants each.
            assert_eq!(r.rows.len(), 9, "{}", r.kind.name());
            assert!(r.rows.iter().all(|row| row.mrays_per_s > 0.0 && row.passes.len() == 1));
            assert!(r.rows.iter().filter(|row| row.target == "obvhs-bvh2").all(|row| row.ratio == Some(1.0)));
            for (name, a) in &r.agreement {
                let min = if name.ends_with("+wt") {
                    99.0
                } else if raytrail_method(name) {
                    100.0
                } else {
                    0.0
                };
                assert!(a.exact_pct() >= min, "{} {name}: {:.2}%", r.kind.name(), a.exact_pct());
            }
        }
        assert!(bench_scene("no/such/scene.obj", &opts, &pools).is_err());
    }

    /// Whether `name` is one of raytrail's methods.
    fn raytrail_method(name: &str) -> bool {
        Method::from_name(name).is_some()
    }
}
