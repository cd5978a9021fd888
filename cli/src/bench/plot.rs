//! The SVG plot, written by hand: one panel per scene, one chart per ray type in it, a group of
//! horizontal bars (Mrays/s, one bar per thread count) per target, the baseline as a dashed line.

use super::report::{BenchReport, RayReport, SceneReport};
use super::table::thousands;
use super::target::TargetKind;
use crate::svg::escape;
use std::fmt::Write;

/// Width of the target-name column.
const LABELS: f64 = 118.0;
/// Width of one ray type's chart.
const CHART: f64 = 250.0;
/// Space right of a chart (value labels overflow into it).
const GAP: f64 = 40.0;
/// Height of one bar.
const BAR: f64 = 7.0;
/// Space between targets.
const SPACE: f64 = 5.0;
/// Height of a panel's title and column headers.
const HEAD: f64 = 40.0;
/// Height of a chart's axis labels.
const AXIS: f64 = 22.0;
/// Height of the plot's title and legend.
const TOP: f64 = 58.0;

/// The plot of a whole run.
pub fn to_svg(r: &BenchReport) -> String {
    let columns = r.scenes.iter().map(|s| s.rays.len()).max().unwrap_or(1).max(1);
    let width = LABELS + columns as f64 * (CHART + GAP) + 10.0;
    let heights: Vec<f64> = r.scenes.iter().map(|s| panel_height(s, r.threads.len())).collect();
    let height = TOP + heights.iter().sum::<f64>() + 10.0;
    let mut svg = String::new();
    let _ = write!(
        svg,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="DejaVu Sans, Arial, sans-serif" font-size="11">"#
    );
    let _ = write!(svg, r##"<rect width="100%" height="100%" fill="white"/>"##
    );
    let most = r.threads.iter().max().copied().unwrap_or(1);
    let fewest = r.threads.iter().min().copied().unwrap_or(1);
    let shading = if r.threads.len() > 1 {
        format!("; solid bar: {most} threads, pale bar: {fewest} thread{}", if fewest == 1 { "" } else { "s" })
    } else {
        format!("; {most} thread{}", if most == 1 { "" } else { "s" })
    };
    text(
        &mut svg,
        10.0,
        20.0,
        "start",
        14.0,
        true,
        &format!(
            "raytrail bench: Mrays/s, median of {} pass{}{shading}",
            r.passes,
            if r.passes == 1 { "" } else { "es" }
        ),
    );
    let present = |k: TargetKind| r.scenes.iter().flat_map(|s| &s.rays).flat_map(|x| &x.rows).any(|row| row.kind == k);
    legend(&mut svg, 10.0, 40.0, &r.baseline, present);
    let mut y = TOP;
    for (s, h) in r.scenes.iter().zip(&heights) {
        panel(&mut svg, s, y, &r.threads, &r.baseline);
        y += h;
    }
    svg.push_str("</svg>\n");
    svg
}

/// Height of one scene's panel.
fn panel_height(s: &SceneReport, threads: usize) -> f64 {
    let targets = s.rays.first().map_or(0, |r| r.agreement.len()) as f64;
    HEAD + targets * (threads.max(1) as f64 * BAR + SPACE) + AXIS
}

/// The colour of a target group.
fn colour(kind: TargetKind) -> &'static str {
    match kind {
        TargetKind::RaytrailBvh2 => "#1f6fb4",
        TargetKind::RaytrailKd => "#2a9d4b",
        TargetKind::RaytrailWide => "#17a5b8",
        TargetKind::RaytrailStream => "#8c5a3c",
        TargetKind::RaytrailAuto => "#555555",
        TargetKind::RaytrailGpu => "#7b3fa0",
        TargetKind::PeerOwnTest => "#e8770e",
        TargetKind::PeerWatertight => "#b2403a",
    }
}

/// The legend of the target groups the run has, and the baseline line.
fn legend(svg: &mut String, x: f64, y: f64, baseline: &str, present: impl Fn(TargetKind) -> bool) {
    let mut x = x;
    for (kind, label) in [
        (TargetKind::RaytrailBvh2, "raytrail BVH2 methods"),
        (TargetKind::RaytrailKd, "raytrail kd methods"),
        (TargetKind::RaytrailWide, "raytrail wide methods"),
        (TargetKind::RaytrailStream, "raytrail stream"),
        (TargetKind::RaytrailAuto, "raytrail auto"),
        (TargetKind::RaytrailGpu, "raytrail on the GPU (wgpu)"),
        (TargetKind::PeerOwnTest, "peer, own triangle test"),
        (TargetKind::PeerWatertight, "peer + raytrail watertight test (+wt)"),
    ] {
        if !present(kind) {
            continue;
        }
        let _ =
            write!(svg, r##"<rect x="{x:.1}" y="{:.1}" width="12" height="10" fill="{}"/>"##, y - 9.0, colour(kind));
        text(svg, x + 16.0, y, "start", 11.0, false, label);
        x += 24.0 + 6.4 * label.len() as f64;
    }
    let _ = write!(
        svg,
        r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="black" stroke-dasharray="3,2"/>"##,
        y - 10.0,
        y + 2.0
    );
    text(svg, x + 5.0, y, "start", 11.0, false, &format!("baseline ({baseline})"));
}

/// One scene's panel at height `y`.
fn panel(svg: &mut String, s: &SceneReport, y: f64, threads: &[usize], baseline: &str) {
    let title =
        format!("{}: {} triangles, {} x {} primary rays", s.name, thousands(s.triangles as u64), s.width, s.height);
    let _ = write!(
        svg,
        r##"<line x1="10" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="#bbbbbb"/>"##,
        y + 4.0,
        LABELS + s.rays.len() as f64 * (CHART + GAP),
        y + 4.0
    );
    text(svg, 10.0, y + 20.0, "start", 13.0, true, &title);
    let Some(first) = s.rays.first() else { return };
    let targets: Vec<&str> = first.agreement.iter().map(|(n, _)| n.as_str()).collect();
    let group = threads.len().max(1) as f64 * BAR + SPACE;
    let kind = |name: &str| first.rows.iter().find(|r| r.target == name).map(|r| (r.kind.is_raytrail(), r.kind));
    let right = LABELS + s.rays.len() as f64 * (CHART + GAP) - GAP;
    for (i, name) in targets.iter().enumerate() {
        let cy = y + HEAD + i as f64 * group + threads.len().max(1) as f64 * BAR / 2.0 + 4.0;
        text(svg, LABELS - 6.0, cy, "end", 11.0, false, name);
        // A rule between raytrail's BVH2 methods, its kd methods and the peers.
        let (a, b) = (kind(name), i.checked_sub(1).and_then(|j| kind(targets[j])));
        let peer = |k: Option<(bool, TargetKind)>| k.is_some_and(|k| !k.0);
        if i > 0 && a != b && !(peer(a) && peer(b)) {
            let ly = y + HEAD + i as f64 * group - SPACE / 2.0 - 0.5;
            let _ = write!(
                svg,
                r##"<line x1="20" y1="{ly:.1}" x2="{right:.1}" y2="{ly:.1}" stroke="#999999" stroke-width="0.6"/>"##
            );
        }
    }
    for (c, r) in s.rays.iter().enumerate() {
        chart(svg, r, LABELS + c as f64 * (CHART + GAP), y, &targets, threads, baseline);
    }
}

/// One ray type's chart with its left edge at `x`, in the panel at height `y`.
fn chart(svg: &mut String, r: &RayReport, x: f64, y: f64, targets: &[&str], threads: &[usize], baseline: &str) {
    let max = r.rows.iter().map(|row| row.mrays_per_s).fold(0.0, f64::max);
    let (step, top) = ticks(max);
    let scale = |v: f64| x + CHART * (v / top).clamp(0.0, 1.0);
    let group = threads.len().max(1) as f64 * BAR + SPACE;
    let bottom = y + HEAD + targets.len() as f64 * group;
    let header =
        format!("{}: {} rays, {} hit (Mrays/s)", r.kind.name(), thousands(r.rays as u64), r.kind.query().name());
    text(svg, x, y + HEAD - 8.0, "start", 11.0, true, &header);
    let mut tick = 0.0;
    while tick <= top * (1.0 + 1e-9) {
        let tx = scale(tick);
        let _ = write!(
            svg,
            r##"<line x1="{tx:.1}" y1="{:.1}" x2="{tx:.1}" y2="{bottom:.1}" stroke="#e4e4e4"/>"##,
            y + HEAD - 3.0
        );
        text(svg, tx, bottom + 13.0, "middle", 10.0, false, &trim(tick));
        tick += step;
    }
    for (i, name) in targets.iter().enumerate() {
        for (k, t) in threads.iter().enumerate() {
            let Some(row) = r.rows.iter().find(|row| row.target == *name && row.threads == *t) else { continue };
            let by = y + HEAD + i as f64 * group + k as f64 * BAR;
            let most = k + 1 == threads.len();
            let _ = write!(
                svg,
                r##"<rect x="{x:.1}" y="{by:.1}" width="{:.1}" height="{:.1}" fill="{}" fill-opacity="{}"/>"##,
                scale(row.mrays_per_s) - x,
                BAR - 1.0,
                colour(row.kind),
                if most { "1" } else { "0.4" }
            );
            if most {
                text(
                    svg,
                    scale(row.mrays_per_s) + 3.0,
                    by + BAR - 0.5,
                    "start",
                    9.0,
                    false,
                    &format!("{:.2}", row.mrays_per_s),
                );
            }
        }
    }
    let _ = write!(
        svg,
        r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{bottom:.1}" stroke="#555555"/>"##,
        y + HEAD - 3.0
    );
    let most = threads.iter().max().copied().unwrap_or(1);
    if let Some(b) = r.rows.iter().find(|row| row.target == baseline && row.threads == most) {
        let bx = scale(b.mrays_per_s);
        let _ = write!(
            svg,
            r##"<line x1="{bx:.1}" y1="{:.1}" x2="{bx:.1}" y2="{bottom:.1}" stroke="black" stroke-dasharray="3,2"/>"##,
            y + HEAD - 3.0
        );
    }
}

/// Tick step and axis end for values up to `max`: steps of 1, 2 or 5 times a power of ten, about
/// five ticks.
fn ticks(max: f64) -> (f64, f64) {
    if max.is_nan() || max <= 0.0 {
        return (1.0, 1.0);
    }
    let raw = max / 5.0;
    let p = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0].into_iter().map(|m| m * p).find(|s| *s >= raw).unwrap_or(10.0 * p);
    (step, (max / step).ceil().max(1.0) * step)
}

/// A tick value without needless decimals.
fn trim(v: f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Writes a text element (with a white halo, so that grid and baseline lines do not cross it).
fn text(svg: &mut String, x: f64, y: f64, anchor: &str, size: f64, bold: bool, s: &str) {
    let weight =
        if bold { r#" font-weight="bold""# } else { r#" stroke="white" stroke-width="2.5" paint-order="stroke""# };
    let _ = write!(
        svg,
        r##"<text x="{x:.1}" y="{y:.1}" text-anchor="{anchor}" font-size="{size}"{weight}>{}</text>"##,
        escape(s)
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::agreement::Agreement;
    use crate::bench::rays::RayKind;
    use crate::bench::report::{Row, SceneReport};

    /// Checks that every tag is closed in order and every `&` starts an entity.
    fn well_formed(svg: &str) -> Result<(), String> {
        let mut open: Vec<String> = Vec::new();
        let mut rest = svg;
        while let Some(i) = rest.find('<') {
            let text = &rest[..i];
            for (k, _) in text.match_indices('&') {
                let entity = &text[k..];
                if !["&amp;", "&lt;", "&gt;", "&quot;"].iter().any(|e| entity.starts_with(e)) {
                    return Err(format!("bare & in {text:?}"));
                }
            }
            let end = rest[i..].find('>').ok_or("unclosed tag")? + i;
            let tag = &rest[i + 1..end];
            if let Some(name) = tag.strip_prefix('/') {
                if open.pop().as_deref() != Some(name) {
                    return Err(format!("</{name}> closes nothing open"));
                }
            } else if !tag.ends_with('/') {
                open.push(tag.split_whitespace().next().unwrap_or("").to_string());
            }
            rest = &rest[end + 1..];
        }
        if open.is_empty() && rest.trim().is_empty() {
            Ok(())
        } else {
            Err(format!("left open: {open:?}"))
        }
    }

    fn tiny() -> BenchReport {
        let row = |target: &str, kind, threads, mrays_per_s| Row {
            target: target.to_string(),
            kind,
            threads,
            passes: vec![0.1],
            median_s: 0.1,
            mrays_per_s,
            ratio: None,
            work: None,
            stream: None,
            kernel: None,
        };
        let rays = RayReport {
            kind: RayKind::Primary,
            rays: 100,
            rows: vec![
                row("stack", TargetKind::RaytrailBvh2, 1, 3.0),
                row("stack", TargetKind::RaytrailBvh2, 2, 5.5),
                row("a<b>&\"c\"", TargetKind::PeerOwnTest, 1, 4.0),
                row("a<b>&\"c\"", TargetKind::PeerOwnTest, 2, 7.25),
            ],
            agreement: vec![
                ("stack".to_string(), Agreement::default()),
                ("a<b>&\"c\"".to_string(), Agreement::default()),
            ],
        };
        BenchReport {
            command: "raytrail bench".to_string(),
            baseline: "a<b>&\"c\"".to_string(),
            passes: 3,
            threads: vec![1, 2],
            scenes: vec![SceneReport {
                name: "tiny & small".to_string(),
                view: super::super::view::View::Outside,
                triangles: 2,
                width: 10,
                height: 10,
                builds: vec![],
                rays: vec![rays],
            }],
        }
    }

    #[test]
    fn svg_of_a_tiny_run_is_well_formed() {
        let svg = to_svg(&tiny());
        well_formed(&svg).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("tiny &amp; small") && svg.contains(">7.25<"));
        // An empty run still makes a valid document.
        let empty = BenchReport { scenes: vec![], ..tiny() };
        well_formed(&to_svg(&empty)).unwrap();
        assert!(well_formed("<a><b></a></b>").is_err() && well_formed("<a>x & y</a>").is_err());
    }

    #[test]
    fn ticks_are_round() {
        assert_eq!(ticks(0.0), (1.0, 1.0));
        assert_eq!(ticks(9.3), (2.0, 10.0));
        assert_eq!(ticks(31.0), (10.0, 40.0));
        let (step, top) = ticks(0.42);
        assert!((step - 0.1).abs() < 1e-12 && (top - 0.5).abs() < 1e-9, "{step} {top}");
    }
}
