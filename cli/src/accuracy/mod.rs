//! `raytrail accuracy`: run time against error, for every method and triangle test.
//!
//! Per scene and camera view (the bench's [`View`]s), the bench's ray sets are made once
//! ([`crate::bench::rays`]; the secondary rays from the stack method's watertight primary hits).
//! Per ray set, an evenly spaced sample of `--sample` rays (Morton order, so it spreads over the
//! image) is answered by the exact reference ([`ExactScene`]: integer arithmetic behind a proven
//! `f64` filter, accelerated by a BVH that only culls boxes the exact ray provably misses, so its
//! answers are the brute force's). Then every method with every triangle test traces the full
//! set once untimed, whose answers on the sample are judged ([`classify`]), and `--passes` times
//! timed (the median is reported; CPU backend, rayon's global pool, all threads).
//!
//! Why a sample rather than every ray: the exact test costs microseconds per candidate triangle,
//! and a sample of a few thousand rays resolves an error rate down to a few in ten thousand,
//! which is what the Pareto plot needs; the sample size is printed with every table.

pub mod classify;
mod plot;
mod report;

use crate::args::{check_distinct, check_input, check_output, AccuracyArgs};
use crate::bench::rays::{self, RayKind};
use crate::bench::view::{Enclosure, View};
use crate::failure::{Failure, Outcome};
use crate::median::median;
use crate::progress::{timed, Progress};
use classify::{classify, Tally};
use rayon::prelude::*;
use raytrail::core::method::{Bvh2Method, Method, Query};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::trace::{Trace, TraceOptions, TriangleTestKind};
use raytrail::core::{Hit, Ray};
use raytrail::cpu::{CpuBackend, CpuScene};
use raytrail::mesh::LoadOptions;
use raytrail::Builder;
use raytrail_cli::write::write_atomically;
use raytrail_conformance::exact::{ExactAnswer, ExactScene, Tolerance};
use report::{AccuracyReport, RaySetReport, Row, SceneReport};
use std::io::Write;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// The default method (`raytrail trace`'s) that the default triangle test is marked with.
pub const DEFAULT_METHOD: Method = Method::Bvh2(Bvh2Method::Hash);

/// Sampled rays answered by the exact reference between two progress steps.
const EXACT_CHUNK: usize = 512;

/// The checked flags.
struct Plan {
    scenes: Vec<std::path::PathBuf>,
    kinds: Vec<RayKind>,
    methods: Vec<Method>,
    tests: Vec<TriangleTestKind>,
    views: Vec<View>,
    auto_view: bool,
    builder: Builder,
    load: LoadOptions,
    width: u32,
    height: u32,
    sample: usize,
    passes: usize,
    ao_rays: usize,
    max_rays: u64,
}

/// Command-line name of a triangle test.
pub fn test_name(t: TriangleTestKind) -> &'static str {
    match t {
        TriangleTestKind::Watertight => "watertight",
        TriangleTestKind::MollerTrumbore => "moller-trumbore",
    }
}

fn plan(a: &AccuracyArgs) -> Result<Plan, Failure> {
    let usage = |m: String| Failure::Usage(m);
    let mut kinds = Vec::new();
    for name in &a.rays {
        let k = RayKind::from_name(name.trim()).ok_or_else(|| {
            usage(format!("--rays: unknown ray type '{name}' (known: {})", RayKind::ALL.map(RayKind::name).join(", ")))
        })?;
        if !kinds.contains(&k) {
            kinds.push(k);
        }
    }
    let backend = CpuBackend::new();
    let mut methods = Vec::new();
    for name in &a.methods {
        let found: Vec<Method> = if name.trim() == "all" {
            Method::ALL.into_iter().filter(|m| backend.supports(*m)).collect()
        } else {
            let m = Method::from_name(name.trim())
                .ok_or_else(|| usage(format!("--methods: unknown method '{name}' (see --help)")))?;
            if !backend.supports(m) {
                return Err(usage(format!("--methods: the CPU backend cannot trace with '{name}'")));
            }
            vec![m]
        };
        for m in found {
            if !methods.contains(&m) {
                methods.push(m);
            }
        }
    }
    let mut tests = Vec::new();
    for name in &a.tests {
        let t = match name.as_str() {
            "watertight" => TriangleTestKind::Watertight,
            _ => TriangleTestKind::MollerTrumbore,
        };
        if !tests.contains(&t) {
            tests.push(t);
        }
    }
    let scenes: Vec<_> = a.scene.iter().flat_map(|list| crate::args::path_list(list)).collect();
    if kinds.is_empty() || methods.is_empty() || tests.is_empty() || scenes.is_empty() {
        return Err(usage("--scene, --rays, --methods and --tests each need at least one value".to_string()));
    }
    let (views, auto_view) = match a.view.as_str() {
        "outside" => (vec![View::Outside], false),
        "inside" => (vec![View::Inside], false),
        "both" => (vec![View::Outside, View::Inside], false),
        _ => (vec![View::Outside, View::Inside], true),
    };
    Ok(Plan {
        scenes,
        kinds,
        methods,
        tests,
        views,
        auto_view,
        builder: crate::flags::builder(&a.builder),
        load: a.load.load_options(),
        width: a.width,
        height: a.height,
        sample: usize::try_from(a.sample).unwrap_or(usize::MAX),
        passes: a.passes as usize,
        ao_rays: a.ao_rays as usize,
        max_rays: a.max_rays,
    })
}

/// Runs `raytrail accuracy`; `args` are the arguments after the subcommand, for the report.
pub fn main(a: AccuracyArgs, args: &[String]) -> Outcome {
    let p = plan(&a)?;
    for (flag, path) in [("json", &a.json), ("plot", &a.plot)] {
        if let Some(path) = path {
            check_output(flag, path)?;
        }
    }
    for path in &p.scenes {
        check_input("scene", path)?;
    }
    let inputs: Vec<_> = p.scenes.iter().map(|s| ("scene", s.as_path())).collect();
    let outputs: Vec<_> = [("json", &a.json), ("plot", &a.plot)]
        .into_iter()
        .filter_map(|(flag, path)| path.as_deref().map(|p| (flag, p)))
        .collect();
    check_distinct(&inputs, &outputs)?;
    let pixels = u64::from(p.width) * u64::from(p.height);
    let most = pixels.saturating_mul(p.ao_rays.max(rays::SOFT_SHADOW_SAMPLES) as u64);
    crate::limits::check_count("rays", most, "max-rays", p.max_rays, 2 * std::mem::size_of::<Ray>() as u64)?;
    let mut scenes = Vec::new();
    for path in &p.scenes {
        for s in measure_scene(path, &p)? {
            report::print_scene(&s);
            scenes.push(s);
        }
    }
    let report = AccuracyReport {
        command: std::iter::once("raytrail accuracy".to_string())
            .chain(args.iter().cloned())
            .collect::<Vec<_>>()
            .join(" "),
        sample: p.sample,
        passes: p.passes,
        threads: rayon::current_num_threads(),
        width: p.width,
        height: p.height,
        tolerance_ulps: Tolerance::ULPS,
        default_method: DEFAULT_METHOD.name().to_string(),
        default_test: test_name(TriangleTestKind::default()).to_string(),
        scenes,
    };
    if let Some(path) = &a.json {
        let cannot = |e: &dyn std::fmt::Display| format!("cannot write {}: {e}", path.display());
        let text = serde_json::to_string_pretty(&report).map_err(|e| cannot(&e))?;
        write_atomically(path, |w| w.write_all(text.as_bytes()).and_then(|_| w.write_all(b"\n")))
            .map_err(|e| cannot(&e))?;
        errln!("wrote {}", path.display());
    }
    if let Some(path) = &a.plot {
        write_atomically(path, |w| w.write_all(plot::to_svg(&report).as_bytes()))
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        errln!("wrote {}", path.display());
    }
    let defaults_wrong: usize = report
        .scenes
        .iter()
        .flat_map(|s| &s.rays)
        .flat_map(|r| &r.rows)
        .filter(|r| r.default)
        .map(|r| r.tally.errors())
        .sum();
    if defaults_wrong > 0 {
        errln!(
            "WARNING: the default ({} with the {} test) answered {defaults_wrong} sampled rays wrongly",
            report.default_method,
            report.default_test
        );
    }
    Ok(0)
}

/// The evenly spaced indices of a sample of `n` out of `len`.
pub fn sample_indices(len: usize, n: usize) -> Vec<usize> {
    if n >= len {
        return (0..len).collect();
    }
    (0..n).map(|i| (i as u128 * len as u128 / n as u128) as usize).collect()
}

/// Loads and prepares one scene, and measures every view of it that is kept.
fn measure_scene(path: &Path, p: &Plan) -> Result<Vec<SceneReport>, String> {
    let (loaded, _) = timed(&format!("loading {}", path.display()), || crate::args::load_scene(path, &p.load));
    let (named, _, warning) = loaded?;
    crate::args::warn(&warning);
    let scene = &named.scene;
    crate::args::ploc_note(p.builder, scene);
    let (bvh, _) =
        timed(&format!("building the BVH2 ({} triangles)", scene.triangles().len()), || p.builder.build(scene));
    let bvh = bvh.map_err(|e| format!("{}: {e}", named.name))?;
    let stack = Method::Bvh2(Bvh2Method::Stack);
    let mut methods = p.methods.clone();
    if !methods.contains(&stack) {
        methods.push(stack);
    }
    let (prepared, _) = timed("deriving layouts, hash tables and trees", || PreparedScene::new(scene, bvh, &methods));
    let cpu = CpuScene(Arc::new(prepared.map_err(|e| format!("{}: {e}", named.name))?));
    let (exact, _) =
        timed("building the exact reference's culling BVH", || ExactScene::new(scene.triangles().to_vec()));
    let tol = Tolerance::for_scene(scene.bounds().max_abs());
    let backend = CpuBackend::new();
    let trace = |rays: &[Ray], opts: &TraceOptions, hits: &mut [Hit]| {
        backend.trace(&cpu, rays, opts, hits).map_err(|e| format!("{}, {}: {e}", named.name, opts.method.name()))
    };
    let mut out = Vec::new();
    for &view in &p.views {
        let primary = rays::primary_rays(scene, view, p.width, p.height);
        let mut primary_hits = vec![Hit::MISS; primary.len()];
        trace(&primary, &TraceOptions::new(stack), &mut primary_hits)?;
        let enclosure = Enclosure::of(&primary, &primary_hits, scene.triangles());
        if p.auto_view && view == View::Inside && !enclosure.is_room() {
            outln!("  inside view of {}: skipped, not a room (--view inside measures it anyway)", named.name);
            continue;
        }
        let batches = rays::batches(&p.kinds, scene, &primary, &primary_hits, p.ao_rays);
        let name = view.label(&named.name);
        let steps: usize = batches
            .iter()
            .map(|b| {
                sample_indices(b.rays.len(), p.sample).len().div_ceil(EXACT_CHUNK) + p.methods.len() * p.tests.len()
            })
            .sum();
        let mut progress = Progress::new(&format!("accuracy {name}"), steps);
        let mut sets = Vec::new();
        for b in &batches {
            let query = b.kind.query();
            let sample = sample_indices(b.rays.len(), p.sample);
            let mut answers: Vec<ExactAnswer> = Vec::with_capacity(sample.len());
            for chunk in sample.chunks(EXACT_CHUNK) {
                answers.par_extend(chunk.par_iter().map(|&i| exact.closest_hit(&b.rays[i])));
                progress.step(&format!("{} exact reference", b.kind.name()));
            }
            let mut rows = Vec::new();
            let mut hits = vec![Hit::MISS; b.rays.len()];
            for &m in &p.methods {
                for &test in &p.tests {
                    let opts = TraceOptions::new(m).query(query).triangle_test(test);
                    trace(&b.rays, &opts, &mut hits)?;
                    let mut tally = Tally::default();
                    for (&i, ans) in sample.iter().zip(&answers) {
                        tally.add(classify(query, &b.rays[i], scene.triangles(), ans, &hits[i], tol));
                    }
                    let mut passes = Vec::with_capacity(p.passes);
                    for _ in 0..p.passes {
                        let start = Instant::now();
                        trace(&b.rays, &opts, &mut hits)?;
                        passes.push(start.elapsed().as_secs_f64());
                    }
                    let secs = median(&passes);
                    rows.push(Row {
                        method: m.name().to_string(),
                        test: test_name(test).to_string(),
                        mrays_per_s: if secs > 0.0 { b.rays.len() as f64 / secs / 1e6 } else { 0.0 },
                        passes_s: passes,
                        error_rate: tally.error_rate(),
                        tally,
                        pareto: false,
                        default: m == DEFAULT_METHOD && test == TriangleTestKind::default(),
                    });
                    progress.step(&format!("{} {} {}", b.kind.name(), m.name(), test_name(test)));
                }
            }
            report::mark_pareto(&mut rows);
            sets.push(RaySetReport {
                kind: b.kind.name().to_string(),
                query: if query == Query::Any { "any" } else { "closest" }.to_string(),
                rays: b.rays.len(),
                sampled: sample.len(),
                rows,
            });
        }
        progress.finish();
        out.push(SceneReport { name, triangles: scene.triangles().len(), rays: sets });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_spread_and_stay_in_range() {
        assert_eq!(sample_indices(10, 20), (0..10).collect::<Vec<_>>());
        assert_eq!(sample_indices(10, 5), vec![0, 2, 4, 6, 8]);
        assert_eq!(sample_indices(0, 5), Vec::<usize>::new());
        let s = sample_indices(1_000_003, 4096);
        assert_eq!(s.len(), 4096);
        assert!(s.windows(2).all(|w| w[0] < w[1]) && *s.last().unwrap() < 1_000_003);
    }
}
