//! The run as JSON, through serde: one object per scene, per ray type, per row.
//!
//! Shape: `{command, baseline, passes, threads, scenes: [{name, view, triangles, width, height,
//! builds: [{what, seconds, bytes: {part: n}}], rays: [{type, query, rays, rows: [{target, kind,
//! threads, mrays_per_s, ratio, median_s, passes_s, nodes_per_ray, leaves_per_ray,
//! tests_per_ray}], agreement: [{target, rays, exact, within_tolerance, classes: {class: n}}]}]}]}`.
//! Figures not measured, and NaN or infinite ones (which JSON lacks), are `null`.
//!
//! The report types stay free of serde; the private views below borrow them and fix the field
//! names and order of the document.

use super::agreement::{Agreement, Class};
use super::report::{BenchReport, Built, RayReport, Row, SceneReport};
use serde::{Serialize, Serializer};
use std::collections::BTreeMap;

/// The whole report as a JSON document (indented, ending in a newline).
pub fn to_json(r: &BenchReport) -> String {
    let doc = Doc {
        command: &r.command,
        baseline: &r.baseline,
        passes: r.passes,
        threads: &r.threads,
        scenes: r.scenes.iter().map(Scene::from).collect(),
    };
    // Serializing these plain structs (string keys, no failing `Serialize` impls) cannot fail.
    let mut out = serde_json::to_string_pretty(&doc).expect("the bench report serializes to JSON");
    out.push('\n');
    out
}

#[derive(Serialize)]
struct Doc<'a> {
    command: &'a str,
    baseline: &'a str,
    passes: usize,
    threads: &'a [usize],
    scenes: Vec<Scene<'a>>,
}

#[derive(Serialize)]
struct Scene<'a> {
    name: &'a str,
    view: &'static str,
    triangles: usize,
    width: u32,
    height: u32,
    builds: Vec<Build<'a>>,
    rays: Vec<Rays<'a>>,
}

impl<'a> From<&'a SceneReport> for Scene<'a> {
    fn from(s: &'a SceneReport) -> Self {
        Scene {
            name: &s.name,
            view: s.view.name(),
            triangles: s.triangles,
            width: s.width,
            height: s.height,
            builds: s.builds.iter().map(Build::from).collect(),
            rays: s.rays.iter().map(Rays::from).collect(),
        }
    }
}

#[derive(Serialize)]
struct Build<'a> {
    what: &'a str,
    seconds: f64,
    /// Part name to bytes, in the report's order.
    #[serde(serialize_with = "pairs_as_map")]
    bytes: &'a [(String, usize)],
}

impl<'a> From<&'a Built> for Build<'a> {
    fn from(b: &'a Built) -> Self {
        Build { what: &b.what, seconds: b.seconds, bytes: &b.bytes }
    }
}

#[derive(Serialize)]
struct Rays<'a> {
    #[serde(rename = "type")]
    kind: &'static str,
    query: &'static str,
    rays: usize,
    rows: Vec<RowView<'a>>,
    agreement: Vec<AgreementView<'a>>,
}

impl<'a> From<&'a RayReport> for Rays<'a> {
    fn from(r: &'a RayReport) -> Self {
        Rays {
            kind: r.kind.name(),
            query: r.kind.query().name(),
            rays: r.rays,
            rows: r.rows.iter().map(RowView::from).collect(),
            agreement: r.agreement.iter().map(|(target, a)| AgreementView::new(target, a)).collect(),
        }
    }
}

#[derive(Serialize)]
struct RowView<'a> {
    target: &'a str,
    kind: &'static str,
    threads: usize,
    mrays_per_s: f64,
    ratio: Option<f64>,
    median_s: f64,
    passes_s: &'a [f64],
    nodes_per_ray: Option<f64>,
    leaves_per_ray: Option<f64>,
    tests_per_ray: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    stream: Option<StreamView<'a>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    kernel: Option<KernelView<'a>>,
}

/// A GPU target's kernel time at steady clocks (its row's own figures are end to end).
#[derive(Serialize)]
struct KernelView<'a> {
    mrays_per_s: f64,
    min_mrays_per_s: f64,
    max_mrays_per_s: f64,
    samples_s: &'a [f64],
    passes_per_sample: usize,
    warm_up_s: f64,
    bytes_per_trace: u64,
}

/// A stream target's stage seconds and working figures.
#[derive(Serialize)]
struct StreamView<'a> {
    packets: usize,
    active_frustums: usize,
    queue_sizes: &'a [u32],
    leaf_refs: usize,
    largest_list: usize,
    box_tests: u64,
    working_bytes: usize,
    sort_s: f64,
    frustums_s: f64,
    traversal_s: f64,
    intersection_s: f64,
}

impl<'a> From<&'a Row> for RowView<'a> {
    fn from(r: &'a Row) -> Self {
        let w = r.work.unwrap_or_default();
        RowView {
            target: &r.target,
            kind: r.kind.name(),
            threads: r.threads,
            mrays_per_s: r.mrays_per_s,
            ratio: r.ratio,
            median_s: r.median_s,
            passes_s: &r.passes,
            nodes_per_ray: w.nodes,
            leaves_per_ray: w.leaves,
            tests_per_ray: w.tests,
            kernel: r.kernel.as_ref().map(|k| {
                let (lo, hi) = k.spread();
                KernelView {
                    mrays_per_s: k.median_mrays_per_s(),
                    min_mrays_per_s: lo,
                    max_mrays_per_s: hi,
                    samples_s: &k.seconds,
                    passes_per_sample: k.passes_per_sample,
                    warm_up_s: k.warm_up_seconds,
                    bytes_per_trace: k.bytes_per_trace,
                }
            }),
            stream: r.stream.as_ref().map(|st| StreamView {
                packets: st.packets,
                active_frustums: st.active_frustums,
                queue_sizes: &st.queue_sizes,
                leaf_refs: st.leaf_refs,
                largest_list: st.largest_list,
                box_tests: st.box_tests,
                working_bytes: st.working_bytes,
                sort_s: st.seconds.sort,
                frustums_s: st.seconds.frustums,
                traversal_s: st.seconds.traversal,
                intersection_s: st.seconds.intersection,
            }),
        }
    }
}

#[derive(Serialize)]
struct AgreementView<'a> {
    target: &'a str,
    rays: usize,
    exact: usize,
    within_tolerance: usize,
    /// Class name to rays, in the classes' order.
    #[serde(serialize_with = "classes_as_map")]
    classes: &'a BTreeMap<Class, usize>,
}

impl<'a> AgreementView<'a> {
    fn new(target: &'a str, a: &'a Agreement) -> Self {
        AgreementView { target, rays: a.rays, exact: a.exact, within_tolerance: a.close, classes: &a.classes }
    }
}

/// `[(key, n)]` as a JSON object, keeping the order.
fn pairs_as_map<S: Serializer>(pairs: &&[(String, usize)], s: S) -> Result<S::Ok, S::Error> {
    s.collect_map(pairs.iter().map(|(k, n)| (k, n)))
}

/// Classes as a JSON object keyed by their report names.
fn classes_as_map<S: Serializer>(classes: &&BTreeMap<Class, usize>, s: S) -> Result<S::Ok, S::Error> {
    s.collect_map(classes.iter().map(|(c, n)| (c.name(), n)))
}

#[cfg(test)]
mod tests {
    use super::super::rays::RayKind;
    use super::super::target::{TargetKind, Work};
    use super::super::view::View;
    use super::*;
    use serde_json::{json, Value};

    fn report() -> BenchReport {
        let row = |target: &str, kind, ratio, work| Row {
            target: target.into(),
            kind,
            threads: 4,
            passes: vec![0.5, 0.25, f64::NAN],
            median_s: 0.25,
            mrays_per_s: 3.0,
            ratio,
            work,
            stream: None,
            kernel: None,
        };
        let agreement = Agreement {
            rays: 10,
            exact: 7,
            close: 8,
            classes: BTreeMap::from([(Class::NearTie, 1), (Class::TieEqualT, 1)]),
        };
        BenchReport {
            command: "raytrail bench --scene \"a b\\c\".ply\n".into(),
            baseline: "stack".into(),
            passes: 3,
            threads: vec![1, 4],
            scenes: vec![SceneReport {
                name: "dragon_vrip.ply.gz — ü".into(),
                view: View::Inside,
                triangles: 12,
                width: 64,
                height: 48,
                builds: vec![Built {
                    what: "raytrail sah".into(),
                    seconds: 1.5,
                    bytes: vec![("nodes".into(), 1024), ("indices".into(), 48)],
                }],
                rays: vec![RayReport {
                    kind: RayKind::Shadow,
                    rays: 10,
                    rows: vec![
                        row(
                            "stack",
                            TargetKind::RaytrailBvh2,
                            Some(1.0),
                            Some(Work { nodes: Some(12.5), leaves: None, tests: Some(f64::INFINITY) }),
                        ),
                        row("obvhs", TargetKind::PeerOwnTest, None, None),
                    ],
                    agreement: vec![("obvhs".into(), agreement)],
                }],
            }],
        }
    }

    #[test]
    fn the_document_has_every_field_with_its_meaning() {
        let text = to_json(&report());
        assert!(text.ends_with("}\n"));
        let doc: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(doc["command"], "raytrail bench --scene \"a b\\c\".ply\n");
        assert_eq!(doc["baseline"], "stack");
        assert_eq!(doc["passes"], 3);
        assert_eq!(doc["threads"], json!([1, 4]));
        let scene = &doc["scenes"][0];
        assert_eq!(scene["name"], "dragon_vrip.ply.gz — ü");
        assert_eq!(scene["view"], "inside");
        assert_eq!((&scene["triangles"], &scene["width"], &scene["height"]), (&json!(12), &json!(64), &json!(48)));
        assert_eq!(
            scene["builds"],
            json!([{"what": "raytrail sah", "seconds": 1.5, "bytes": {"nodes": 1024, "indices": 48}}])
        );
        let rays = &scene["rays"][0];
        assert_eq!((&rays["type"], &rays["query"], &rays["rays"]), (&json!("shadow"), &json!("any"), &json!(10)));
        assert_eq!(
            rays["rows"][0],
            json!({"target": "stack", "kind": "raytrail-bvh2", "threads": 4, "mrays_per_s": 3.0, "ratio": 1.0,
                   "median_s": 0.25, "passes_s": [0.5, 0.25, null], "nodes_per_ray": 12.5,
                   "leaves_per_ray": null, "tests_per_ray": null})
        );
        assert_eq!(rays["rows"][1]["ratio"], Value::Null);
        assert_eq!(rays["rows"][1]["nodes_per_ray"], Value::Null);
        assert_eq!(
            rays["agreement"],
            json!([{"target": "obvhs", "rays": 10, "exact": 7, "within_tolerance": 8,
                    "classes": {"tie-equal-t": 1, "near-tie": 1}}])
        );
    }

    #[test]
    fn keys_keep_the_report_order() {
        let text = to_json(&report());
        let at = |key: &str| text.find(&format!("\"{key}\"")).unwrap_or_else(|| panic!("{key} missing"));
        let order = ["command", "baseline", "passes", "threads", "scenes", "name", "view", "builds", "rays", "rows"];
        assert!(order.windows(2).all(|w| at(w[0]) < at(w[1])), "{text}");
        // Maps keep the report's order too (not sorted): "nodes" before "indices".
        assert!(at("nodes") < at("indices"));
        assert!(at("tie-equal-t") < at("near-tie"));
    }
}
