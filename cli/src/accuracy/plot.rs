//! The SVG plot of `raytrail accuracy`, written by hand: one chart per scene and ray type, Mrays/s
//! across, the error rate up (a band for zero, then decades on a log scale), one marker per
//! method and test (circle: watertight, triangle: Möller-Trumbore; colour: the structure), the
//! Pareto front filled and joined by a line, the default ringed.

use super::report::{AccuracyReport, RaySetReport};
use crate::svg::escape;
use raytrail::core::method::{Method, Structure};
use std::fmt::Write;

/// Width and height of one chart's plotting area.
const W: f64 = 280.0;
const H: f64 = 170.0;
/// Space left of (axis labels), below (axis title) and above (chart title) a chart.
const LEFT: f64 = 52.0;
const BELOW: f64 = 34.0;
const ABOVE: f64 = 22.0;
/// Space right of a chart.
const RIGHT: f64 = 18.0;
/// Height of the zero band at the bottom of the error axis.
const ZERO_BAND: f64 = 18.0;
/// Height of the plot's title and legend.
const TOP: f64 = 64.0;

/// Colour of a method's structure.
fn colour(method: &str) -> &'static str {
    match Method::from_name(method).map(Method::structure) {
        Some(Structure::Bvh2) => "#1f6fb4",
        Some(Structure::Kd) => "#2a9d4b",
        Some(Structure::Wide) => "#e07b00",
        Some(Structure::Levels) => "#7b3fa0",
        _ => "#555555",
    }
}

fn text(svg: &mut String, x: f64, y: f64, anchor: &str, size: f64, s: &str) {
    let _ =
        write!(svg, r#"<text x="{x:.1}" y="{y:.1}" text-anchor="{anchor}" font-size="{size}">{}</text>"#, escape(s));
}

/// A marker: circle for watertight, triangle otherwise; filled on the front.
fn marker(svg: &mut String, x: f64, y: f64, test: &str, fill: &str, stroke: &str) {
    if test == "watertight" {
        let _ = write!(svg, r#"<circle cx="{x:.1}" cy="{y:.1}" r="4" fill="{fill}" stroke="{stroke}"/>"#);
    } else {
        let _ = write!(
            svg,
            r#"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" fill="{fill}" stroke="{stroke}"/>"#,
            x,
            y - 5.0,
            x - 4.5,
            y + 3.5,
            x + 4.5,
            y + 3.5
        );
    }
}

/// The plot of a whole run.
pub fn to_svg(r: &AccuracyReport) -> String {
    let columns = r.scenes.iter().map(|s| s.rays.len()).max().unwrap_or(1).max(1);
    let (cw, ch) = (LEFT + W + RIGHT, ABOVE + H + BELOW);
    let width = columns as f64 * cw + 10.0;
    let height = TOP + r.scenes.len().max(1) as f64 * ch + 10.0;
    // The error axis starts at the decade of one ray in the largest sample.
    let most = r.scenes.iter().flat_map(|s| &s.rays).map(|x| x.sampled).max().unwrap_or(1).max(1);
    let low = -(most as f64).log10().ceil();
    let mut svg = String::new();
    let _ = write!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="DejaVu Sans, Arial, sans-serif" font-size="10">"#
    );
    svg.push_str(r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = write!(
        svg,
        r#"<text x="10" y="18" font-size="13" font-weight="bold">{}</text>"#,
        escape(&format!(
            "raytrail accuracy: Mrays/s (median of {} passes, {} threads, CPU) against the share of sampled rays \
             answered wrongly (exact reference)",
            r.passes, r.threads
        ))
    );
    text(
        &mut svg,
        10.0,
        36.0,
        "start",
        10.0,
        &format!(
            "circle: watertight, triangle: Möller-Trumbore; blue BVH2, green kd-tree, orange wide BVH, purple stream; \
             filled and joined: the Pareto front; ringed: the default ({} {})",
            r.default_method, r.default_test
        ),
    );
    text(&mut svg, 10.0, 52.0, "start", 10.0, &format!("command: {}", r.command));
    for (si, s) in r.scenes.iter().enumerate() {
        for (ci, set) in s.rays.iter().enumerate() {
            let x0 = ci as f64 * cw + LEFT;
            let y0 = TOP + si as f64 * ch + ABOVE;
            chart(&mut svg, x0, y0, &s.name, set, low);
        }
    }
    svg.push_str("</svg>\n");
    svg
}

/// One chart with its plotting area's top left at `(x0, y0)`; the error axis from `10^low` to 1.
fn chart(svg: &mut String, x0: f64, y0: f64, scene: &str, set: &RaySetReport, low: f64) {
    text(svg, x0 + W / 2.0, y0 - 8.0, "middle", 11.0, &format!("{scene}: {} ({} sampled)", set.kind, set.sampled));
    let _ = write!(svg, r##"<rect x="{x0:.1}" y="{y0:.1}" width="{W}" height="{H}" fill="none" stroke="#999"/>"##);
    let top_speed = set.rows.iter().map(|r| r.mrays_per_s).fold(0.0f64, f64::max).max(1e-9) * 1.08;
    let xs = |v: f64| x0 + W * v / top_speed;
    let zero_y = y0 + H - ZERO_BAND / 2.0;
    let ys = |e: f64| {
        if e <= 0.0 {
            zero_y
        } else {
            let f = ((e.log10() - low) / -low).clamp(0.0, 1.0);
            y0 + (H - ZERO_BAND) * (1.0 - f)
        }
    };
    // Error axis: the zero band and the decades.
    let _ = write!(
        svg,
        r##"<line x1="{x0:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="#ccc" stroke-dasharray="3,3"/>"##,
        y0 + H - ZERO_BAND,
        x0 + W,
        y0 + H - ZERO_BAND
    );
    text(svg, x0 - 4.0, zero_y + 3.0, "end", 9.0, "0");
    for d in (low as i32)..=0 {
        let y = ys(10f64.powi(d));
        let _ = write!(svg, r##"<line x1="{:.1}" y1="{y:.1}" x2="{x0:.1}" y2="{y:.1}" stroke="#999"/>"##, x0 - 3.0);
        let decimals = (-(d + 2)).max(0) as usize;
        text(svg, x0 - 5.0, y + 3.0, "end", 9.0, &format!("{:.*}%", decimals, 100.0 * 10f64.powi(d)));
    }
    // Speed axis: five ticks.
    for k in 0..=4 {
        let v = top_speed * k as f64 / 4.0;
        let x = xs(v);
        let _ = write!(
            svg,
            r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#999"/>"##,
            y0 + H,
            y0 + H + 3.0
        );
        text(svg, x, y0 + H + 13.0, "middle", 9.0, &format!("{v:.1}"));
    }
    text(svg, x0 + W / 2.0, y0 + H + 26.0, "middle", 9.0, "Mrays/s");
    // The front, joined in order of speed.
    let mut front: Vec<(f64, f64)> =
        set.rows.iter().filter(|r| r.pareto).map(|r| (xs(r.mrays_per_s), ys(r.error_rate))).collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    if front.len() > 1 {
        let pts: Vec<String> = front.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
        let _ = write!(svg, r##"<polyline points="{}" fill="none" stroke="#333" stroke-width="1"/>"##, pts.join(" "));
    }
    for r in &set.rows {
        let (x, y) = (xs(r.mrays_per_s), ys(r.error_rate));
        let c = colour(&r.method);
        marker(svg, x, y, &r.test, if r.pareto { c } else { "white" }, c);
        if r.default {
            let _ = write!(
                svg,
                r##"<circle cx="{x:.1}" cy="{y:.1}" r="8" fill="none" stroke="#d00" stroke-width="1.5"/>"##
            );
        }
        if r.pareto || r.default {
            let label = if r.test == "watertight" { r.method.clone() } else { format!("{} (MT)", r.method) };
            let label = if r.default { format!("{label}, default") } else { label };
            let _ = write!(
                svg,
                r#"<text x="{:.1}" y="{:.1}" font-size="8" transform="rotate(-35 {:.1} {:.1})">{}</text>"#,
                x + 5.0,
                y - 6.0,
                x + 5.0,
                y - 6.0,
                escape(&label)
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::classify::Tally;
    use super::super::report::{Row, SceneReport};
    use super::*;

    #[test]
    fn the_plot_marks_the_front_and_the_default() {
        let row = |method: &str, test: &str, speed: f64, err: f64, pareto: bool, default: bool| Row {
            method: method.to_string(),
            test: test.to_string(),
            mrays_per_s: speed,
            passes_s: vec![],
            error_rate: err,
            tally: Tally::default(),
            pareto,
            default,
        };
        let set = RaySetReport {
            kind: "primary".into(),
            query: "closest".into(),
            rays: 100,
            sampled: 100,
            rows: vec![
                row("hash", "watertight", 2.0, 0.0, true, true),
                row("kd-stack", "moller-trumbore", 3.0, 0.02, true, false),
                row("bvh4", "watertight", 1.0, 0.0, false, false),
            ],
        };
        let r = AccuracyReport {
            command: "raytrail accuracy --scene a<b".into(),
            sample: 100,
            passes: 3,
            threads: 2,
            width: 10,
            height: 10,
            tolerance_ulps: 64.0,
            default_method: "hash".into(),
            default_test: "watertight".into(),
            scenes: vec![SceneReport { name: "s".into(), triangles: 1, rays: vec![set] }],
        };
        let svg = to_svg(&r);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("a&lt;b") && !svg.contains("a<b"));
        assert_eq!(svg.matches("<polyline").count(), 1);
        assert_eq!(svg.matches(r##"stroke="#d00""##).count(), 1);
        assert!(svg.contains(">hash, default<") && svg.contains(">kd-stack (MT)<") && !svg.contains(">bvh4<"));
        // 100 rays: the error axis runs from 1% to 100%.
        assert!(svg.contains(">1%<") && svg.contains(">100%<") && !svg.contains(">0.1%<"));
    }
}
