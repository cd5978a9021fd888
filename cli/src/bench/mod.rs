//! `raytrail bench`: raytrail's methods against peer libraries (obvhs's BVH2 and CWBVH, the `bvh`
//! crate, and Embree with the `embree` cargo feature) on the same rays, in the same process, on
//! the same thread pools.
//!
//! Per scene: build raytrail's tree, layouts and tables and each peer's own tree once; then per
//! camera view ([`view`]: outside the scene, and inside it where it is a room) make primary,
//! shadow, diffuse and ambient-occlusion rays (the secondary rays from the stack method's primary
//! hits); time every target at each thread count ([`measure`]); compare every target's hits with
//! the stack method's ([`agreement`]). Then print tables ([`table`]) and optionally write JSON
//! ([`json`]) and an SVG plot ([`plot`]), one scene entry per view.

mod agreement;
mod json;
mod measure;
pub mod options;
mod peers;
mod plot;
pub(crate) mod rays;
mod report;
mod table;
mod target;
mod target_auto;
mod target_gpu;
pub mod view;

use crate::args::{check_distinct, check_input, check_output};
use crate::failure::{Failure, Outcome};
use crate::progress::{timed, Progress};
use options::Options;
use raytrail::core::bvh2::SahConfig;
use raytrail::core::method::{Bvh2Method, Method, Query};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::trace::Trace;
use raytrail::core::Hit;
use raytrail::cpu::CpuScene;
use raytrail::gpu::WgpuBackend;
use raytrail::mesh::LoadOptions;
use raytrail::Builder;
use raytrail_cli::write::write_atomically;
use report::{BenchReport, Built, SceneReport};
use std::io::Write;
use std::path::Path;
use std::sync::Arc;
use target::{BenchTarget, RaytrailCpu, Targets};
use target_gpu::RaytrailGpu;
use view::Enclosure;

/// Runs `raytrail bench` with its flags; `args` are the arguments after the subcommand, as given,
/// for the report.
pub fn main(a: options::BenchArgs, args: &[String]) -> Outcome {
    let opts = Options::from_args(&a).map_err(Failure::Usage)?;
    check_baseline(&opts).map_err(Failure::Usage)?;
    if let Some(path) = &opts.json {
        check_output("json", path)?;
    }
    if let Some(path) = &opts.plot {
        check_output("plot", path)?;
    }
    for path in &opts.scenes {
        check_input("scene", path)?;
    }
    let inputs: Vec<_> = opts.scenes.iter().map(|s| ("scene", s.as_path())).collect();
    let outputs: Vec<_> = [("json", &opts.json), ("plot", &opts.plot)]
        .into_iter()
        .filter_map(|(flag, path)| path.as_deref().map(|p| (flag, p)))
        .collect();
    check_distinct(&inputs, &outputs)?;
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
        let print = &mut |s: &SceneReport| table::print_scene(s, &opts.baseline, opts.passes);
        scenes.extend(bench_scene(path, &opts, &pools, print)?);
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
        write_atomically(path, |w| w.write_all(json::to_json(&report).as_bytes()))
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        errln!("wrote {}", path.display());
    }
    if let Some(path) = &opts.plot {
        write_atomically(path, |w| w.write_all(plot::to_svg(&report).as_bytes()))
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        errln!("wrote {}", path.display());
    }
    Ok(0)
}

/// Fails early when `--baseline` names no target of this run.
fn check_baseline(opts: &Options) -> Result<(), String> {
    let mut names: Vec<String> = opts.methods.iter().map(|m| m.name().to_string()).collect();
    if opts.auto {
        names.push(crate::flags::AUTO.to_string());
    }
    for p in &opts.peers {
        names.extend(peers::target_names(p));
    }
    let best_of_embree = opts.baseline == measure::EMBREE_BEST
        && ["embree", "embree-high"].iter().all(|p| opts.peers.iter().any(|q| q == p));
    if best_of_embree || names.contains(&opts.baseline) {
        Ok(())
    } else {
        Err(format!(
            "--baseline: '{}' is not measured in this run (measured: {}; '{}' needs the peers embree and \
             embree-high)",
            opts.baseline,
            names.join(", "),
            measure::EMBREE_BEST
        ))
    }
}

/// Loads, builds, and per view of [`Options::view`] makes rays and measures every target on one
/// scene; one report per view, in order, each also handed to `done` as soon as it is measured. The
/// trees are built once and serve every view.
fn bench_scene(
    path: &Path,
    opts: &Options,
    pools: &[(usize, rayon::ThreadPool)],
    done: &mut dyn FnMut(&SceneReport),
) -> Result<Vec<SceneReport>, String> {
    let options = LoadOptions { strict: opts.strict, ..LoadOptions::default() };
    let (loaded, _) = timed(&format!("loading {}", path.display()), || crate::args::load_scene(path, &options));
    let (named, _, warning) = loaded?;
    crate::args::warn(&warning);
    let scene = &named.scene;
    let largest = &pools.last().ok_or("no thread pool")?.1;
    crate::args::ploc_note(opts.builder, scene);

    let (bvh, tree_s) = timed(
        &format!("building raytrail's BVH2 ({}, {} triangles)", opts.builder.name(), scene.triangles().len()),
        || largest.install(|| opts.builder.build_choosing(scene)),
    );
    let (bvh, made_by) = bvh.map_err(|e| format!("{}: {e}", named.name))?;
    // The stack method always takes part: it makes the secondary rays and the reference hits.
    let mut methods = opts.methods.clone();
    if !methods.contains(&Method::Bvh2(Bvh2Method::Stack)) {
        methods.push(Method::Bvh2(Bvh2Method::Stack));
    }
    // `auto` times its candidates, so their tables must be there.
    if opts.auto {
        methods.extend(raytrail::analysis::choice::CANDIDATES.iter().filter(|m| !opts.methods.contains(m)));
    }
    let (prepared, _) = timed("deriving raytrail's layouts, hash tables and kd-tree", || {
        largest.install(|| PreparedScene::new(scene, bvh, &methods))
    });
    let prepared = Arc::new(prepared.map_err(|e| format!("{}: {e}", named.name))?);
    let mut builds = raytrail_builds(opts.builder, made_by, tree_s, &prepared);
    let cpu = CpuScene(prepared);

    let stack = RaytrailCpu::new(Method::Bvh2(Bvh2Method::Stack), cpu.clone());
    let mut targets: Targets = Vec::new();
    for &m in &opts.methods {
        if m.stream().is_some() {
            for &params in &opts.stream {
                targets.push(Box::new(RaytrailCpu::stream(m, params, cpu.clone())));
            }
        } else {
            for &order in &opts.trace_orders {
                targets.push(Box::new(RaytrailCpu::new(m, cpu.clone()).in_order(order)));
            }
        }
    }
    let auto_log = if opts.auto {
        let auto = target_auto::AutoTarget::new(cpu.clone());
        let log = auto.choices.clone();
        targets.push(Box::new(auto));
        Some(log)
    } else {
        None
    };
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
    let mut reports = Vec::new();
    for &view in opts.view.views() {
        let primary = opts.order.primary_rays(scene, view, opts.width, opts.height);
        let mut primary_hits = vec![Hit::MISS; primary.len()];
        stack.trace(largest, &primary, Query::Closest, &mut primary_hits)?;
        let enclosure = Enclosure::of(&primary, &primary_hits, scene.triangles());
        if !opts.view.keeps(view, &enclosure) {
            outln!(
                "  {} view of {}: skipped, not a room ({:.1}% of its primary rays hit, {:.1}% of those a front side; \
                 --view both measures it anyway)",
                view.name(),
                named.name,
                100.0 * enclosure.hits,
                100.0 * enclosure.front
            );
            continue;
        }
        let mut batches = rays::batches(&opts.rays, scene, &primary, &primary_hits, opts.ao_rays);
        opts.order.arrange(&mut batches);
        let mut references = Vec::with_capacity(batches.len());
        for b in &batches {
            let mut hits = vec![Hit::MISS; b.rays.len()];
            stack.trace(largest, &b.rays, b.kind.query(), &mut hits)?;
            references.push(hits);
        }
        let name = view.label(&named.name);
        let mut progress = Progress::new(&format!("bench {name}"), plan.steps_per_batch() * batches.len());
        let mut rays = Vec::with_capacity(batches.len());
        for (b, reference) in batches.iter().zip(&references) {
            rays.push(plan.run(b, reference, &mut progress)?);
        }
        progress.finish();
        if let Some(log) = &auto_log {
            print_auto_choices(&name, log, &rays, pools);
        }
        let report = SceneReport {
            name,
            view,
            triangles: scene.triangles().len(),
            width: opts.width,
            height: opts.height,
            builds: builds.clone(),
            rays,
        };
        done(&report);
        reports.push(report);
    }
    Ok(reports)
}

/// Prints (and forgets) the choices `auto` made for a view's batches, each with its cost against
/// the median time of one `auto` trace of the batch at the same thread count.
fn print_auto_choices(
    view: &str,
    log: &std::sync::Mutex<Vec<(usize, raytrail::analysis::choice::Choice)>>,
    reports: &[report::RayReport],
    pools: &[(usize, rayon::ThreadPool)],
) {
    let Ok(mut log) = log.lock() else { return };
    // One choice per batch and thread count, in the order measured (the work pass reuses the
    // last one).
    for (i, (n, c)) in log.drain(..).enumerate() {
        let (report, threads) = (reports.get(i / pools.len().max(1)), pools.get(i % pools.len().max(1)).map(|p| p.0));
        let report = report.filter(|r| r.rays == n);
        let batch_s = report
            .and_then(|r| r.rows.iter().find(|row| row.target == crate::flags::AUTO && Some(row.threads) == threads))
            .map_or(f64::NAN, |row| row.median_s);
        let kind = report.map_or("?", |r| r.kind.name());
        outln!(
            "  auto [{view}, {kind}, {} thr]: {} on a {}-ray sample; choosing took {:.2} ms = {:.1}% of one trace of \
             the batch; {}",
            threads.unwrap_or(0),
            c.method,
            raytrail::analysis::sample::sample_size(n),
            1e3 * c.cost_seconds,
            100.0 * c.cost_seconds / batch_s,
            c.summary()
        );
    }
}

/// raytrail's build steps and the memory of each part it derived; `made_by` is the builder whose
/// tree `asked` kept (itself, but for `best`). The tree's SAH cost, what `best` compares, is shown
/// whatever the builder, so that runs with `--builder sah` and `--builder ploc` show what `best`
/// weighed.
fn raytrail_builds(asked: Builder, made_by: Builder, tree_s: f64, p: &PreparedScene) -> Vec<Built> {
    let cost = SahConfig::default().tree_cost(&p.bvh);
    let what = format!("raytrail BVH2 ({}; SAH cost {cost:.2})", asked.label(made_by));
    let mut out = vec![Built { what, seconds: tree_s, bytes: vec![] }];
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
            outln!("  GPU: skipped ({e})");
            return Ok(Vec::new());
        }
    };
    let kernel = if backend.has_gpu_timer() {
        "kernels alone by GPU timestamps at steady clocks"
    } else {
        "no kernel time (no timestamp queries)"
    };
    outln!("  GPU: {}; passes timed end to end by the wall clock, {kernel}", backend.adapter());
    let scene = Arc::new(backend.prepare(cpu.0.clone()).map_err(|e| e.to_string())?);
    let mut targets: Targets = Vec::new();
    for config in &opts.gpu {
        let b = Arc::new(backend.configured(*config).map_err(|e| format!("--gpu-dispatch/--gpu-workgroup: {e}"))?);
        for m in opts.methods.iter().copied().filter(|m| m.stream().is_none()) {
            targets.push(Box::new(RaytrailGpu::new(m, b.clone(), scene.clone(), opts.gpu_warm_up)));
        }
    }
    // The stream method's kernels have their own dispatch: one target, `gpu:stream`.
    for m in opts.methods.iter().copied().filter(|m| m.stream().is_some()) {
        targets.push(Box::new(RaytrailGpu::new(m, backend.clone(), scene.clone(), opts.gpu_warm_up)));
    }
    Ok(targets)
}

#[cfg(test)]
mod tests {
    use super::*;
    use view::View;

    #[test]
    fn a_tiny_run_measures_every_target_and_agrees() {
        let args: Vec<String> =
            "--width 24 --height 16 --passes 1 --threads 1 --methods stack,hash,kd-stack --ao-rays 2 --builder ploc --no-gpu --view both"
                .split_whitespace()
                .map(str::to_string)
                .collect();
        let opts = Options::parse(&args).unwrap();
        let pools = vec![(1, rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap())];
        let mut printed = Vec::new();
        let views = bench_scene(Path::new("builtin"), &opts, &pools, &mut |s| printed.push(s.name.clone())).unwrap();
        assert_eq!(views.iter().map(|s| s.view).collect::<Vec<_>>(), [View::Outside, View::Inside]);
        assert_eq!(printed, views.iter().map(|s| s.name.clone()).collect::<Vec<_>>());
        assert!(views[1].name.ends_with(" (inside)") && !views[0].name.contains("inside"));
        // 3 methods, 3 peers with 2 variants each, and Embree at two build qualities (own test
        // only) with its feature.
        let rows = if cfg!(feature = "embree") { 11 } else { 9 };
        for s in &views {
            assert_eq!(s.rays.len(), rays::RayKind::ALL.len());
            assert!(s.builds.iter().any(|b| b.what.starts_with("obvhs-cwbvh")));
            assert_eq!(s.builds.iter().any(|b| b.what.starts_with("embree")), cfg!(feature = "embree"));
            for r in &s.rays {
                assert_eq!(r.rows.len(), rows, "{} {}", s.name, r.kind.name());
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
                    assert!(a.exact_pct() >= min, "{} {} {name}: {:.2}%", s.name, r.kind.name(), a.exact_pct());
                }
            }
        }
        assert!(bench_scene(Path::new("no/such/scene.obj"), &opts, &pools, &mut |_| {}).is_err());
        // From inside, the sphereflake's eye is within its big sphere: no room, so `auto` (the
        // default) measures the outside view only.
        let args: Vec<String> = args.iter().take_while(|a| *a != "--view").cloned().collect();
        let opts = Options::parse(&args).unwrap();
        let views = bench_scene(Path::new("builtin"), &opts, &pools, &mut |_| {}).unwrap();
        assert_eq!(views.iter().map(|s| s.view).collect::<Vec<_>>(), [View::Outside]);
    }

    #[test]
    fn the_baseline_must_be_measured() {
        let parse = |s: &str| Options::parse(&s.split_whitespace().map(str::to_string).collect::<Vec<_>>()).unwrap();
        assert!(check_baseline(&parse("--peers bvh --baseline bvh+wt")).is_ok());
        assert!(check_baseline(&parse("--peers bvh --baseline obvhs-bvh2")).is_err());
        if cfg!(feature = "embree") {
            assert!(check_baseline(&parse("--peers embree --baseline embree")).is_ok());
            assert!(check_baseline(&parse("--peers embree,embree-high --baseline embree-best")).is_ok());
            assert!(check_baseline(&parse("--peers embree --baseline embree-best")).is_err());
            // Embree has no watertight variant.
            assert!(check_baseline(&parse("--peers embree --baseline embree+wt")).is_err());
        }
    }

    /// Whether `name` is one of raytrail's methods.
    fn raytrail_method(name: &str) -> bool {
        Method::from_name(name).is_some()
    }
}
