//! The main job: build, prepare, trace primary, shadow and diffuse rays with every method, and
//! report speed, work per ray, state size, hash-table figures, what `--method auto` picks per ray
//! set, and the conformance verdict.

use crate::args::{check_input, load_scene, warn, RunArgs};
use crate::failure::Outcome;
use crate::flags::builder;
use crate::limits::check_image;
use crate::median::median;
use crate::progress::{timed, Progress};
use raytrail::core::method::{Bvh2Method, KdMethod, Method, Query};
use raytrail::core::observe::Counters;
use raytrail::core::prepared::{BuiltHash, PreparedScene};
use raytrail::core::stream::StreamStats;
use raytrail::core::trace::{Record, Trace, TraceOptions};
use raytrail::core::wide::WideStats;
use raytrail::core::{Hit, Ray};
use raytrail::cpu::{CpuBackend, CpuScene};
use raytrail::Builder;
use raytrail_conformance::check::{check_ray_set, Context, Mismatch};
use raytrail_conformance::rays::{default_light, diffuse, primary, scene_epsilon, shadow, RAY_SEED};
use std::sync::Arc;

/// One method's figures on a ray set: median seconds and counters.
type Row = (Method, f64, Counters);

/// One ray set's results: rows, rays checked, CPU mismatches, GPU seconds per method and GPU
/// mismatches (when the GPU ran).
struct SetResult<'a> {
    set: &'a RaySetRun,
    rows: Vec<Row>,
    checked: usize,
    mismatches: Vec<Mismatch>,
    gpu: Option<(Vec<crate::gpu::GpuTimes>, Vec<Mismatch>)>,
    /// The stream method's working figures and stages (its counted run).
    stream: Option<StreamStats>,
    /// Rays refused as outside the supported numeric range (the most any method refused).
    refused: usize,
    /// What `--method auto` chooses for the set (the default method of `trace`); `None` for a
    /// set without rays (the shadow and diffuse rays of a scene whose camera rays hit nothing).
    auto: Option<raytrail::analysis::choice::Choice>,
}

struct RaySetRun {
    name: &'static str,
    query: Query,
    rays: Vec<Ray>,
}

pub fn main(a: RunArgs) -> Outcome {
    let scene_arg = a.scene.as_path();
    let builder = builder(&a.builder);
    let (width, height) = (a.width, a.height);
    let passes = a.passes as usize;
    let check_rays = a.check_rays;
    // Rays and hits of the three sets, held at once.
    check_image(width, height, "rays per set", "max-rays", a.max_rays, 3 * 48)?;
    check_input("scene", scene_arg)?;
    let backend = match a.threads {
        Some(n) => CpuBackend::with_threads(n as usize).map_err(|e| e.to_string())?,
        None => CpuBackend::new(),
    };

    let (loaded, _) =
        timed(&format!("loading {}", scene_arg.display()), || load_scene(scene_arg, &a.load.load_options()));
    let (named, _, warning) = loaded?;
    warn(&warning);
    let scene = &named.scene;
    crate::args::ploc_note(builder, scene);
    let (bvh, build_s) =
        timed(&format!("building the BVH2 ({}, {} triangles)", builder.name(), scene.triangles().len()), || {
            builder.build(scene)
        });
    let bvh = bvh.map_err(|e| e.to_string())?;
    let (prepared, _) =
        timed("deriving layouts and hash tables for every method", || PreparedScene::new(scene, bvh, &Method::ALL));
    let prepared = Arc::new(prepared.map_err(|e| e.to_string())?);
    print_scene(&named.name, builder, build_s, &prepared);

    let cpu = backend.prepare(prepared.clone()).map_err(|e| e.to_string())?;
    let gpu = if a.no_gpu { Err("--no-gpu".to_string()) } else { crate::gpu::Gpu::open(prepared.clone()) };
    match &gpu {
        Ok(g) => outln!("  GPU: {}", g.describe()),
        Err(why) => outln!("  GPU: skipped ({why}); the CPU figures follow"),
    }
    let gpu = gpu.ok();
    let sets = ray_sets(&backend, &cpu, scene, width, height)?;
    let mut failures: Vec<Mismatch> = Vec::new();
    let gpu_steps = if gpu.is_some() { sets.len() * (Method::ALL.len() + 1) } else { 0 };
    let mut progress =
        Progress::new("tracing", sets.len() * Method::ALL.len() * (passes + 1) + 2 * sets.len() + gpu_steps);
    let mut tables = Vec::new();
    for set in &sets {
        let mut rows = Vec::new();
        let mut stream = None;
        let mut refused = 0;
        for method in Method::ALL {
            let mut opts = TraceOptions::new(method).query(set.query);
            let mut hits = vec![Hit::MISS; set.rays.len()];
            let mut times = Vec::with_capacity(passes);
            for _ in 0..passes {
                let r = backend.trace(&cpu, &set.rays, &opts, &mut hits).map_err(|e| e.to_string())?;
                times.push(r.seconds);
                progress.step(&format!("{} {}", set.name, method));
            }
            opts.record = Record::Counters;
            let counted = backend.trace(&cpu, &set.rays, &opts, &mut hits).map_err(|e| e.to_string())?;
            progress.step(&format!("{} {} counters", set.name, method));
            stream = stream.or(counted.stream);
            refused = refused.max(counted.refused);
            rows.push((method, median(&times), counted.counters.unwrap_or_default()));
        }
        let auto = if set.rays.is_empty() {
            None
        } else {
            let c = raytrail::analysis::sample::choose_on_cpu(&backend, &cpu, &set.rays, set.query);
            Some(c.map_err(|e| format!("auto: {e}"))?)
        };
        progress.step(&format!("{} auto", set.name));
        // Conformance on an evenly spread subset: recording every node of every ray is heavy.
        let step = set.rays.len().div_ceil(check_rays.max(1)).max(1);
        let subset: Vec<Ray> = set.rays.iter().step_by(step).copied().collect();
        let ctx = Context { scene: &named.name, ray_set: set.name, backend: backend.name() };
        let mismatches = check_ray_set(&backend, &cpu, ctx, &subset, &Method::ALL).map_err(|e| e.to_string())?;
        progress.step(&format!("{} conformance", set.name));
        failures.extend(mismatches.clone());
        let gpu_result = match &gpu {
            Some(g) => {
                let mut secs = Vec::new();
                for method in Method::ALL {
                    secs.push(g.time(&set.rays, method, set.query, passes)?);
                    progress.step(&format!("{} {} on the GPU", set.name, method));
                }
                let ctx = Context { scene: &named.name, ray_set: set.name, backend: "wgpu" };
                let gm = g.check(&backend, &cpu, ctx, &subset)?;
                progress.step(&format!("{} GPU conformance", set.name));
                failures.extend(gm.clone());
                Some((secs, gm))
            }
            None => None,
        };
        tables.push(SetResult { set, rows, checked: subset.len(), mismatches, gpu: gpu_result, stream, refused, auto });
    }
    progress.finish();
    for t in &tables {
        print_table(t, &prepared);
    }
    let per_set: Vec<(&str, Vec<Row>)> = tables.iter().map(|t| (t.set.name, t.rows.clone())).collect();
    print_backtracking(&per_set);
    print_kd(&per_set);
    print_stream(&tables);
    let camera = sets.first().map_or(&[][..], |s| s.rays.as_slice());
    let query_failures = crate::queries::print_queries(&backend, gpu.as_ref(), &prepared, scene, builder, camera)?;
    let refused: Vec<String> = tables
        .iter()
        .filter(|t| t.refused > 0)
        .map(|t| format!("{} {} of {}", t.refused, t.set.name, t.set.rays.len()))
        .collect();
    if !refused.is_empty() {
        outln!(
            "\nREFUSED rays (outside the supported numeric range, docs/NUMERICS-RANGE.md; answered as refused, never as misses): {}",
            refused.join(", ")
        );
    }
    if failures.is_empty() {
        outln!(
            "\nconformance: every method matches its reference on every checked ray (hits and node enumerations){}{}.",
            if gpu.is_some() { ", on the GPU as on the CPU, and the GPU matches the CPU ray by ray" } else { "" },
            if refused.is_empty() { "" } else { "; refused rays are left out of that: see above" }
        );
    } else {
        outln!("\nCONFORMANCE FAILED: {} mismatches. The first ones:", failures.len());
        for m in failures.iter().take(5) {
            outln!("{m}");
        }
    }
    if query_failures > 0 {
        outln!("\nQUERY CHECKS FAILED: {query_failures} lists, points, instanced hits or refit hits differ (see the queries table)");
    }
    Ok(if failures.is_empty() && query_failures == 0 { 0 } else { 1 })
}

fn ray_sets(
    backend: &CpuBackend,
    cpu: &CpuScene,
    scene: &raytrail::core::scene::Scene,
    w: u32,
    h: u32,
) -> Result<Vec<RaySetRun>, String> {
    let prim = primary(scene, w, h);
    let mut hits = vec![Hit::MISS; prim.len()];
    backend
        .trace(cpu, &prim, &TraceOptions::new(Method::Bvh2(Bvh2Method::Stack)), &mut hits)
        .map_err(|e| e.to_string())?;
    let bounds = scene.bounds();
    let shadow_rays = shadow(&prim, &hits, default_light(bounds), scene_epsilon(bounds));
    let diffuse_rays = diffuse(&prim, &hits, scene, RAY_SEED);
    Ok(vec![
        RaySetRun { name: "primary", query: Query::Closest, rays: prim },
        RaySetRun { name: "shadow", query: Query::Any, rays: shadow_rays },
        RaySetRun { name: "diffuse", query: Query::Closest, rays: diffuse_rays },
    ])
}

fn mb(bytes: usize) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

fn print_scene(name: &str, builder: Builder, build_s: f64, p: &PreparedScene) {
    let s = p.bvh.stats();
    outln!(
        "\nscene {name}: {} internal nodes, {} leaves (largest {}), depth {}, {} keys (the {} path)",
        s.internal_nodes,
        s.leaves,
        s.max_leaf_size,
        s.depth,
        s.key_width,
        if s.key_width == raytrail::core::key::KeyWidth::W32 {
            "fast 32-bit"
        } else {
            "64-bit, as the depth exceeds 31"
        }
    );
    outln!(
        "  BVH2 ({}) built in {:.3} s; layouts {:.1} MB (nodes and leaf triangles) in {:.1} ms",
        builder.name(),
        build_s,
        mb(p.bvh_bytes()),
        1e3 * p.timings.layouts
    );
    let describe = |label: &str, h: &Option<BuiltHash>, secs: f64| {
        if let Some(h) = h {
            let st = &h.stats;
            outln!(
                "  {label}: {} keys of {} nodes, D = {}, H = {}, {} direct, {:.2} MB = +{:.1}% of the BVH, built in {:.1} ms ({} batches, {} growths)",
                st.keys, p.bvh.len(), st.d_size, st.h_size, st.direct, mb(st.bytes),
                100.0 * st.bytes as f64 / p.bvh_bytes().max(1) as f64, 1e3 * secs, st.batches, st.growths
            );
        }
    };
    describe("hash tables (backtracking targets)", &p.hash, p.timings.hash);
    describe("hash tables (every node, for resuming)", &p.full_hash, p.timings.full_hash);
    let binary_node_bytes = s.internal_nodes * core::mem::size_of::<raytrail::core::bvh2::BinaryNode>();
    let wide = |label: &str, st: Option<WideStats>| {
        if let Some(w) = st {
            outln!(
                "  {label}: {} nodes ({:.0}% of the binary tree's), {} empty slots, depth {}, {:.2} MB of nodes ({:+.0}% against the binary nodes' {:.2} MB)",
                w.nodes, 100.0 * w.nodes as f64 / s.internal_nodes.max(1) as f64, w.empty_slots, w.depth,
                mb(w.node_bytes), 100.0 * (w.node_bytes as f64 / binary_node_bytes.max(1) as f64 - 1.0), mb(binary_node_bytes)
            );
        }
    };
    wide("4-wide BVH (pull-up)", p.wide4.as_ref().map(|t| t.stats()));
    wide("8-wide BVH (pull-up)", p.wide8.as_ref().map(|t| t.stats()));
    wide("4-wide BVH (every second level)", p.wide4_naive.as_ref().map(|t| t.stats()));
    if p.wide4.is_some() || p.wide8.is_some() || p.wide4_naive.is_some() {
        outln!("  wide trees collapsed in {:.1} ms", 1e3 * p.timings.wide);
    }
    match &p.wide4_hash {
        Some(Ok(h)) => {
            let (st, nodes) = (&h.hash.stats, p.wide4.as_ref().map_or(0, |t| t.stats().node_bytes));
            outln!(
                "  hash tables (4-wide node keys, bvh4-hash): {} keys, {} keys and trails, D = {}, H = {}, {} direct, {:.2} MB = +{:.1}% of the 4-wide nodes, built in {:.1} ms",
                st.keys, h.keys, st.d_size, st.h_size, st.direct, mb(st.bytes),
                100.0 * st.bytes as f64 / nodes.max(1) as f64, 1e3 * p.timings.wide_hash
            );
        }
        Some(Err(e)) => outln!("  hash tables (4-wide node keys, bvh4-hash): none, {e}"),
        None => {}
    }
    if let Some(kd) = &p.kd {
        let k = kd.tree.stats();
        outln!(
            "  kd-tree (SAH, traversal cost = intersection cost): {} inner nodes, {} leaves ({} empty, largest {}), depth {}, {:.2} references per triangle, {:.1} MB, built in {:.3} s",
            k.inner_nodes, k.leaves, k.empty_leaves, k.max_leaf_size, k.depth, k.refs_per_triangle,
            mb(kd.tree.bytes()), p.timings.kd
        );
    }
}

fn per_ray(x: u64, c: &Counters) -> f64 {
    x as f64 / c.rays.max(1) as f64
}

fn print_table(t: &SetResult<'_>, prepared: &PreparedScene) {
    let set = t.set;
    outln!(
        "\n{} rays: {} ({} hit), median of timed passes; conformance on {} rays",
        set.name,
        set.rays.len(),
        set.query.name(),
        t.checked
    );
    let gpu_head = if t.gpu.is_some() { format!(" {:>9} {:>9}", "GPU e2e", "GPU kern") } else { String::new() };
    outln!(
        "  {:<15} {:>9} {:>10}{gpu_head} {:>10} {:>12} {:>10} {:>10} {:>8}  conformance",
        "method",
        "Mrays/s",
        "vs stack",
        "nodes/ray",
        "backtr./ray",
        "hash/ray",
        "links/ray",
        "state B"
    );
    let stack_s = t.rows.iter().find(|r| r.0 == Method::Bvh2(Bvh2Method::Stack)).map_or(0.0, |r| r.1);
    for (i, (m, secs, c)) in t.rows.iter().enumerate() {
        let mut bad = t.mismatches.iter().filter(|x| x.method == *m).count();
        let gpu_col = match &t.gpu {
            Some((secs, gm)) => {
                bad += gm.iter().filter(|x| x.method == *m).count();
                let mrays = |s: f64| set.rays.len() as f64 / s / 1e6;
                let kernel = secs[i].kernel.map_or("-".to_string(), |k| format!("{:.2}", mrays(k)));
                format!(" {:>9.2} {kernel:>9}", mrays(secs[i].end_to_end))
            }
            None => String::new(),
        };
        outln!(
            "  {:<15} {:>9.2} {:>9.2}x{gpu_col} {:>10.1} {:>12.2} {:>10.2} {:>10.2} {:>8}  {}",
            m.name(),
            set.rays.len() as f64 / secs / 1e6,
            stack_s / secs,
            per_ray(c.nodes(), c),
            per_ray(c.backtracks, c),
            per_ray(c.hash_lookups(), c),
            per_ray(c.link_reads, c),
            prepared.state_bytes(*m),
            if bad == 0 { "ok".to_string() } else { format!("MISMATCH on {bad} checks") }
        );
    }
    // What `--method auto` (the default of `raytrail trace`) picks here, and against what.
    let Some(a) = &t.auto else {
        outln!("  auto: no rays to choose on (the camera rays hit nothing, so there are no {} rays)", set.name);
        return;
    };
    let chosen_s = t.rows.iter().find(|r| r.0 == a.method).map_or(f64::NAN, |r| r.1);
    let fastest = t.rows.iter().min_by(|x, y| x.1.total_cmp(&y.1));
    outln!(
        "  auto: {} ({:.2} Mrays/s above; the fastest is {}), chosen on a {}-ray sample in {:.2} ms = {:.1}% of one trace",
        a.method,
        set.rays.len() as f64 / chosen_s / 1e6,
        fastest.map_or("?".to_string(), |f| format!("{} at {:.2}", f.0, set.rays.len() as f64 / f.1 / 1e6)),
        raytrail::analysis::sample::sample_size(set.rays.len()),
        1e3 * a.cost_seconds,
        100.0 * a.cost_seconds / chosen_s
    );
}

/// Interior nodes per ray of the kd methods against the kd stack traversal (Horn et al. 2007,
/// Sec. 5.1.1: push-down visits 3-22% fewer nodes than restart, short-stack 48-52% fewer again,
/// and short-stack within 3% of an unbounded stack).
fn print_kd(sets: &[(&str, Vec<Row>)]) {
    outln!("\nkd-tree interior nodes visited per ray, and the ratio to the kd stack traversal (restarts per ray):");
    out!("  {:<9}", "rays");
    for m in Method::KD {
        out!(" {:>22}", m.name());
    }
    outln!();
    for (name, rows) in sets {
        let get = |m: Method| rows.iter().find(|r| r.0 == m).map(|r| r.2);
        let Some(base) = get(Method::Kd(KdMethod::Stack)) else { continue };
        let base_inner = per_ray(base.internal_nodes, &base);
        out!("  {:<9}", name);
        for m in Method::KD {
            let c = get(m).unwrap_or_default();
            let inner = per_ray(c.internal_nodes, &c);
            out!(
                " {:>22}",
                format!("{:.1} ({:.2}x, {:.2})", inner, inner / base_inner.max(1e-9), per_ray(c.restarts, &c))
            );
        }
        outln!();
    }
}

/// The stream method's packets, leaf lists and stages per ray set (Garanzha & Loop 2010, Table 1
/// and Fig. 13).
fn print_stream(tables: &[SetResult<'_>]) {
    outln!("\nstream method (Garanzha & Loop 2010): packets, frustum leaf lists and stage times (ms):");
    outln!(
        "  {:<9} {:>8} {:>8} {:>10} {:>8} {:>7} {:>9} {:>10} {:>13}",
        "rays",
        "packets",
        "rays/pk",
        "leaves/pk",
        "longest",
        "sort",
        "frustums",
        "traversal",
        "intersection"
    );
    for t in tables {
        let Some(st) = &t.stream else { continue };
        let per = |x: usize| x as f64 / st.packets.max(1) as f64;
        let ms = |s: f64| format!("{:.2}", s * 1e3);
        outln!(
            "  {:<9} {:>8} {:>8.1} {:>10.1} {:>8} {:>7} {:>9} {:>10} {:>13}",
            t.set.name,
            st.packets,
            per(t.set.rays.len()),
            per(st.leaf_refs),
            st.largest_list,
            ms(st.seconds.sort),
            ms(st.seconds.frustums),
            ms(st.seconds.traversal),
            ms(st.seconds.intersection)
        );
    }
}

fn print_backtracking(sets: &[(&str, Vec<Row>)]) {
    outln!("\nbacktracking steps of the hash method (Binder & Keller 2016, Fig. 3), share of all steps:");
    outln!(
        "  {:<9} {:>10} {:>10} {:>10} {:>11} {:>10} {:>10}   levels climbed 0..6, 7+",
        "rays",
        "postponed",
        "uncle",
        "g-uncle",
        "gg-uncle",
        "hash",
        "direct"
    );
    for (name, rows) in sets {
        let Some((_, _, c)) = rows.iter().find(|r| r.0 == Method::Bvh2(Bvh2Method::Hash)) else { continue };
        let total = c.backtracks.max(1) as f64;
        let pct = |x: u64| format!("{:.1}%", 100.0 * x as f64 / total);
        let levels: Vec<String> = c.levels.iter().map(|&l| format!("{:.0}", 100.0 * l as f64 / total)).collect();
        outln!(
            "  {:<9} {:>10} {:>10} {:>10} {:>11} {:>10} {:>10}   {}%",
            name,
            pct(c.register[0]),
            pct(c.register[1]),
            pct(c.register[2]),
            pct(c.register[3]),
            pct(c.hash[0]),
            pct(c.hash[1]),
            levels.join(" ")
        );
    }
    outln!("  (register: postponed = stored on postponing; uncle, g-uncle, gg-uncle = loaded from links; hash: through the table; direct: from the displacement entry)");
}
