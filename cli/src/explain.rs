//! `raytrail explain SCENE [--rays FILE]`: what the scene needs (the analysis of
//! `raytrail::analysis`), as a table and optionally JSON.

use crate::args::{check_distinct, check_input, check_output, load_scene, warn, ExplainArgs};
use crate::bench::rays::{batches, primary_rays, RayKind};
use crate::bench::view::{Enclosure, ViewChoice};
use crate::failure::Outcome;
use crate::flags::builder;
use crate::limits::{check_count, check_image};
use crate::progress::{timed, Progress};
use raytrail::analysis::{analyze, RaySet, SceneAnalysis};
use raytrail::core::method::{Bvh2Method, Method, Query};
use raytrail::core::prepared::{Part, PreparedScene};
use raytrail::core::scene::Scene;
use raytrail::core::trace::{Trace, TraceOptions};
use raytrail::core::Hit;
use raytrail::cpu::CpuBackend;
use raytrail_cli::npy;
use raytrail_cli::write::write_atomically;
use std::io::Write;
use std::sync::Arc;

/// Ambient-occlusion rays per primary hit in the generated sets (as the bench's default).
const AO_RAYS: usize = 4;

pub fn main(a: ExplainArgs) -> Outcome {
    if let Some(path) = &a.json {
        check_output("json", path)?;
    }
    check_input("scene", &a.scene)?;
    if let Some(r) = &a.rays {
        check_input("rays", r)?;
    } else {
        check_image(a.width, a.height, "rays per set", "max-rays", a.max_rays, 48)?;
    }
    let mut inputs = vec![("scene", a.scene.as_path())];
    inputs.extend(a.rays.as_deref().map(|r| ("rays", r)));
    let outputs: Vec<_> = a.json.as_deref().map(|j| ("json", j)).into_iter().collect();
    check_distinct(&inputs, &outputs)?;
    let view = ViewChoice::from_name(&a.view).map_err(crate::failure::Failure::Usage)?;
    let builder = builder(&a.builder);
    let (loaded, _) = timed(&format!("loading {}", a.scene.display()), || load_scene(&a.scene, &a.load.load_options()));
    let (named, _, warning) = loaded?;
    warn(&warning);
    let scene = &named.scene;
    crate::args::ploc_note(builder, scene);
    let (bvh, build_s) =
        timed(&format!("building the BVH2 ({} triangles)", scene.triangles().len()), || builder.build_choosing(scene));
    let (bvh, made_by) = bvh.map_err(|e| e.to_string())?;
    let backend = CpuBackend::new();
    let sets = match &a.rays {
        Some(path) => {
            let rays = npy::read_rays(path).map_err(|e| e.to_string())?;
            check_count("rays", rays.len() as u64, "max-rays", a.max_rays, 48)?;
            if rays.is_empty() {
                let path = path.display();
                return Err(format!("--rays: {path} holds no rays: there is nothing to choose a method for").into());
            }
            let query = if a.any { Query::Any } else { Query::Closest };
            vec![RaySet { label: path.display().to_string(), query, rays }]
        }
        None => generated_sets(&backend, scene, &bvh, view, a.width, a.height)?,
    };
    let mut progress = Progress::new("analysing", Part::ALL.len() + sets.len());
    let analysis = analyze(scene, &bvh, &sets, &backend, &mut |what| progress.step(what)).map_err(|e| e.to_string())?;
    progress.finish();
    print(&named.name, &builder.label(made_by), build_s, &analysis);
    if let Some(path) = &a.json {
        let text = serde_json::to_string_pretty(&to_json(&named.name, &analysis)).map_err(|e| e.to_string())?;
        let shown = path.display();
        write_atomically(path, |w| w.write_all(text.as_bytes())).map_err(|e| format!("cannot write {shown}: {e}"))?;
        errln!("wrote {shown}");
    }
    Ok(0)
}

/// The bench's ray types from each camera view `view` keeps, labelled `kind` or `kind (inside)`.
fn generated_sets(
    backend: &CpuBackend,
    scene: &Scene,
    bvh: &raytrail::core::bvh2::Bvh2,
    view: ViewChoice,
    width: u32,
    height: u32,
) -> Result<Vec<RaySet>, String> {
    let stack = Method::Bvh2(Bvh2Method::Stack);
    let prepared = PreparedScene::new(scene, bvh.clone(), &[stack]).map_err(|e| e.to_string())?;
    let cpu = backend.prepare(Arc::new(prepared)).map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    for &v in view.views() {
        let primary = primary_rays(scene, v, width, height);
        let mut hits = vec![Hit::MISS; primary.len()];
        backend.trace(&cpu, &primary, &TraceOptions::new(stack), &mut hits).map_err(|e| e.to_string())?;
        if !view.keeps(v, &Enclosure::of(&primary, &hits, scene.triangles())) {
            continue;
        }
        for b in batches(&RayKind::ALL, scene, &primary, &hits, AO_RAYS) {
            if b.rays.is_empty() {
                continue;
            }
            let label = if v.name() == "outside" { b.kind.name().to_string() } else { v.label(b.kind.name()) };
            out.push(RaySet { label, query: b.kind.query(), rays: b.rays });
        }
    }
    Ok(out)
}

fn mb(bytes: usize) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

fn yes_no(b: bool) -> &'static str {
    if b {
        "needed"
    } else {
        "not needed"
    }
}

fn print(name: &str, builder: &str, build_s: f64, a: &SceneAnalysis) {
    outln!(
        "\nscene {name}: {} triangles; BVH2 ({builder}) built in {:.3} s, depth {}, {} keys; canonical tree {:.2} MB",
        a.triangles,
        build_s,
        a.depth,
        a.key_width,
        mb(a.tree_bytes)
    );
    outln!("\ntables, each built alone:");
    outln!("  {:<26} {:>9} {:>10}  read by", "part", "MB", "build ms");
    for p in &a.parts {
        let readers: Vec<&str> =
            Method::ALL.iter().filter(|m| Part::of(**m).contains(&p.part)).map(|m| m.name()).collect();
        outln!("  {:<26} {:>9.2} {:>10.1}  {}", p.part.name(), mb(p.bytes), 1e3 * p.seconds, readers.join(", "));
    }
    outln!("\ntables per method (MB):");
    let per: Vec<String> = Method::ALL.iter().map(|&m| format!("{} {:.2}", m.name(), mb(a.method_bytes(m)))).collect();
    for line in per.chunks(6) {
        outln!("  {}", line.join(", "));
    }
    if !a.choices.is_empty() {
        outln!("\nmethod per ray set (candidates timed on a sample on the CPU):");
        outln!(
            "  {:<22} {:<7} {:>9} {:>7} {:<10} {:>9} {:>9}  candidates, in",
            "rays",
            "query",
            "rays",
            "sample",
            "chosen",
            "choose ms",
            "% batch"
        );
        for c in &a.choices {
            outln!(
                "  {:<22} {:<7} {:>9} {:>7} {:<10} {:>9.2} {:>8.1}%  {}",
                c.label,
                c.query.name(),
                c.rays,
                c.sample,
                c.choice.method.name(),
                1e3 * c.choice.cost_seconds,
                100.0 * c.choice.cost_seconds / c.batch_seconds.max(1e-12),
                c.choice.summary()
            );
        }
    }
    let n = &a.needs;
    outln!("\nwhat the chosen methods need:");
    for (what, need) in [
        ("64-bit keys", &n.keys64),
        ("hash tables", &n.hash_tables),
        ("f64 fallback", &n.f64_fallback),
        ("disjoint mask", &n.disjoint_mask),
        ("slack", &n.slack),
    ] {
        outln!("  {:<14} {:<11} {}", what, yes_no(need.needed), need.why);
    }
    let chosen = a.chosen();
    let (chosen_bytes, chosen_s) = a.cost_of(&chosen);
    let (all_bytes, all_s) = a.cost_of(&Method::ALL);
    let variants = a.variants();
    let all_variants = raytrail::analysis::shaders::all_variant_count(a.key_width);
    outln!(
        "\nwhat it saves: tables {:.2} MB for {} against {:.2} MB for every method; built in {:.0} ms against {:.0} ms; \
         {} wgpu kernels ({:.0} KB of WGSL) against {} for this key width",
        mb(chosen_bytes),
        if chosen.is_empty() { "no method".to_string() } else { names(&chosen) },
        mb(all_bytes),
        1e3 * chosen_s,
        1e3 * all_s,
        variants.len(),
        raytrail::analysis::shaders::source_bytes(&variants) as f64 / 1024.0,
        all_variants
    );
    for v in &variants {
        outln!("  kernel {}", v.label());
    }
}

fn names(methods: &[Method]) -> String {
    methods.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
}

fn to_json(name: &str, a: &SceneAnalysis) -> serde_json::Value {
    use serde_json::json;
    let need = |n: &raytrail::analysis::needs::Need| json!({ "needed": n.needed, "why": n.why });
    let chosen = a.chosen();
    let (chosen_bytes, chosen_s) = a.cost_of(&chosen);
    let (all_bytes, all_s) = a.cost_of(&Method::ALL);
    let variants = a.variants();
    json!({
        "scene": name,
        "triangles": a.triangles,
        "depth": a.depth,
        "key_bits": a.key_width.bytes() * 8,
        "tree_bytes": a.tree_bytes,
        "parts": a.parts.iter().map(|p| json!({
            "part": p.part.name(), "bytes": p.bytes, "build_s": p.seconds,
        })).collect::<Vec<_>>(),
        "methods": Method::ALL.iter().map(|&m| json!({
            "method": m.name(),
            "parts": Part::of(m).iter().map(|p| p.name()).collect::<Vec<_>>(),
            "bytes": a.method_bytes(m),
        })).collect::<Vec<_>>(),
        "choices": a.choices.iter().map(|c| json!({
            "rays": c.label,
            "query": c.query.name(),
            "count": c.rays,
            "sample": c.sample,
            "refused": c.refused,
            "chosen": c.choice.method.name(),
            "choose_s": c.choice.cost_seconds,
            "batch_s": c.batch_seconds,
            "candidates": c.choice.timed.iter().map(|t| json!({
                "method": t.method.name(), "first_look_s": t.first, "rounds_s": t.seconds, "dropped": t.pruned(),
            })).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "needs": {
            "keys64": need(&a.needs.keys64),
            "hash_tables": need(&a.needs.hash_tables),
            "f64_fallback": need(&a.needs.f64_fallback),
            "disjoint_mask": need(&a.needs.disjoint_mask),
            "slack": need(&a.needs.slack),
        },
        "saves": {
            "chosen_bytes": chosen_bytes, "all_bytes": all_bytes,
            "chosen_build_s": chosen_s, "all_build_s": all_s,
            "kernels": variants.iter().map(|v| v.label()).collect::<Vec<_>>(),
            "kernel_wgsl_bytes": raytrail::analysis::shaders::source_bytes(&variants),
            "all_kernels": raytrail::analysis::shaders::all_variant_count(a.key_width),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_sets_cover_every_ray_kind() {
        let scene = crate::args::builtin_scene().scene;
        let bvh = raytrail::Builder::Sah.build(&scene).unwrap();
        let sets = generated_sets(&CpuBackend::new(), &scene, &bvh, ViewChoice::Outside, 16, 12).unwrap();
        let labels: Vec<&str> = sets.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(labels, RayKind::ALL.map(RayKind::name));
        assert!(sets.iter().all(|s| !s.rays.is_empty()));
        assert_eq!(sets.iter().map(|s| s.query).collect::<Vec<_>>(), RayKind::ALL.map(RayKind::query));
    }
}
