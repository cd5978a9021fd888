//! The run as JSON, written by hand (no serde): one object per scene, per ray type, per row.
//!
//! Shape: `{command, baseline, passes, threads, scenes: [{name, triangles, width, height,
//! builds: [{what, seconds, bytes: {part: n}}], rays: [{type, query, rays, rows: [{target, kind,
//! threads, mrays_per_s, ratio, median_s, passes_s, nodes_per_ray, leaves_per_ray,
//! tests_per_ray}], agreement: [{target, rays, exact, within_tolerance, classes: {class: n}}]}]}]}`.
//! Figures not measured are `null`.

use super::report::{BenchReport, Built, RayReport, Row, SceneReport};

/// The whole report as a JSON document.
pub fn to_json(r: &BenchReport) -> String {
    let scenes: Vec<String> = r.scenes.iter().map(scene).collect();
    let threads: Vec<String> = r.threads.iter().map(|t| t.to_string()).collect();
    format!(
        "{{\n\"command\": {},\n\"baseline\": {},\n\"passes\": {},\n\"threads\": [{}],\n\"scenes\": [\n{}\n]\n}}\n",
        string(&r.command),
        string(&r.baseline),
        r.passes,
        threads.join(", "),
        scenes.join(",\n")
    )
}

/// One scene.
fn scene(s: &SceneReport) -> String {
    let builds: Vec<String> = s.builds.iter().map(built).collect();
    let rays: Vec<String> = s.rays.iter().map(ray_report).collect();
    format!(
        "{{\"name\": {}, \"triangles\": {}, \"width\": {}, \"height\": {},\n \"builds\": [\n  {}\n ],\n \"rays\": [\n{}\n ]}}",
        string(&s.name),
        s.triangles,
        s.width,
        s.height,
        builds.join(",\n  "),
        rays.join(",\n")
    )
}

/// One build step.
fn built(b: &Built) -> String {
    let bytes: Vec<String> = b.bytes.iter().map(|(k, n)| format!("{}: {n}", string(k))).collect();
    format!(
        "{{\"what\": {}, \"seconds\": {}, \"bytes\": {{{}}}}}",
        string(&b.what),
        number(b.seconds),
        bytes.join(", ")
    )
}

/// One ray type.
fn ray_report(r: &RayReport) -> String {
    let rows: Vec<String> = r.rows.iter().map(row).collect();
    let agreement: Vec<String> = r
        .agreement
        .iter()
        .map(|(target, a)| {
            let classes: Vec<String> = a.classes.iter().map(|(c, n)| format!("{}: {n}", string(c.name()))).collect();
            format!(
                "{{\"target\": {}, \"rays\": {}, \"exact\": {}, \"within_tolerance\": {}, \"classes\": {{{}}}}}",
                string(target),
                a.rays,
                a.exact,
                a.close,
                classes.join(", ")
            )
        })
        .collect();
    format!(
        "  {{\"type\": {}, \"query\": {}, \"rays\": {},\n   \"rows\": [\n    {}\n   ],\n   \"agreement\": [\n    {}\n   ]}}",
        string(r.kind.name()),
        string(r.kind.query().name()),
        r.rays,
        rows.join(",\n    "),
        agreement.join(",\n    ")
    )
}

/// One row.
fn row(r: &Row) -> String {
    let passes: Vec<String> = r.passes.iter().map(|&s| number(s)).collect();
    let w = r.work.unwrap_or_default();
    let opt = |x: Option<f64>| x.map_or("null".to_string(), number);
    format!(
        "{{\"target\": {}, \"kind\": {}, \"threads\": {}, \"mrays_per_s\": {}, \"ratio\": {}, \"median_s\": {}, \"passes_s\": [{}], \"nodes_per_ray\": {}, \"leaves_per_ray\": {}, \"tests_per_ray\": {}}}",
        string(&r.target),
        string(r.kind.name()),
        r.threads,
        number(r.mrays_per_s),
        opt(r.ratio),
        number(r.median_s),
        passes.join(", "),
        opt(w.nodes),
        opt(w.leaves),
        opt(w.tests)
    )
}

/// A JSON number; `null` for NaN and infinities, which JSON lacks.
fn number(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        "null".to_string()
    }
}

/// A JSON string literal: quotes, backslashes and control characters escaped.
pub fn string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_are_escaped() {
        assert_eq!(string("plain"), "\"plain\"");
        assert_eq!(string("a \"b\" \\ c"), "\"a \\\"b\\\" \\\\ c\"");
        assert_eq!(string("line\nnext\ttab\u{1}"), "\"line\\nnext\\ttab\\u0001\"");
        assert_eq!(string("dragon_vrip.ply.gz — ü"), "\"dragon_vrip.ply.gz — ü\"");
    }

    #[test]
    fn numbers_are_valid_json() {
        assert_eq!(number(1.5), "1.5");
        assert_eq!(number(3.0), "3");
        assert_eq!(number(f64::NAN), "null");
        assert_eq!(number(f64::INFINITY), "null");
    }
}
