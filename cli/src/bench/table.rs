//! The terminal tables: per scene its builds and memory, then per ray type one row per target with
//! a speed and ratio column per thread count, work per ray and hit agreement.

use super::report::{mb, RayReport, Row, SceneReport};

/// Prints everything measured on one scene to standard output.
pub fn print_scene(s: &SceneReport, baseline: &str, passes: usize) {
    outln!("\n== {}: {} triangles; {} x {} primary rays ==", s.name, thousands(s.triangles as u64), s.width, s.height);
    outln!("builds and memory:");
    for b in &s.builds {
        let bytes: Vec<String> = b.bytes.iter().map(|(what, n)| format!("{what} {:.1} MB", mb(*n))).collect();
        let total: usize = b.bytes.iter().map(|(_, n)| n).sum();
        let total = if b.bytes.len() > 1 { format!(" = {:.1} MB", mb(total)) } else { String::new() };
        let line = format!("  {:<46} {:>8.3} s   {}{}", b.what, b.seconds, bytes.join(", "), total);
        outln!("{}", line.trim_end());
    }
    for r in &s.rays {
        print_rays(r, baseline, passes);
    }
}

/// Prints one ray type's table and the disagreement classes below it.
fn print_rays(r: &RayReport, baseline: &str, passes: usize) {
    let threads: Vec<usize> = dedup(r.rows.iter().map(|row| row.threads));
    let any = r.kind.query() == raytrail::core::traverse::Query::Any;
    outln!(
        "\n{} rays: {} ({} hit); Mrays/s = median of {passes} pass{}; ratio = speed / {baseline} at the same threads",
        r.kind.name(),
        thousands(r.rays as u64),
        r.kind.query().name(),
        if passes == 1 { "" } else { "es" }
    );
    // Names of a sweep's targets (`gpu:bvh8/persistent/32`) are longer than most.
    let width = r.agreement.iter().map(|(name, _)| name.len()).max().unwrap_or(0).max(20);
    let mut header = format!("  {:<width$}", "target");
    for t in &threads {
        header += &format!(" {:>8} {:>7}", format!("{t} thr"), "ratio");
    }
    header += &format!(" {:>9} {:>10} {:>9}", "nodes/ray", "leaves/ray", "tests/ray");
    header += if any { "  same occlusion" } else { "  same hit  within 1e-5" };
    outln!("{header}");
    for (name, agreement) in &r.agreement {
        let mut line = format!("  {name:<width$}");
        let mut work = None;
        for t in &threads {
            match r.rows.iter().find(|row| &row.target == name && row.threads == *t) {
                Some(row) => {
                    let ratio = row.ratio.map_or("-".to_string(), |x| format!("{x:.2}x"));
                    line += &format!(" {:>8.2} {:>7}", row.mrays_per_s, ratio);
                    work = work.or(row.work);
                }
                None => line += &format!(" {:>8} {:>7}", "-", "-"),
            }
        }
        let w = work.unwrap_or_default();
        line += &format!(" {:>9} {:>10} {:>9}", opt(w.nodes), opt(w.leaves), opt(w.tests));
        if any {
            line += &format!("  {:>13.3}%", agreement.exact_pct());
        } else {
            line += &format!("  {:>7.3}%  {:>10.3}%", agreement.exact_pct(), agreement.close_pct());
        }
        outln!("{line}");
    }
    if let Some(&most) = threads.last() {
        let best = |raytrail: bool| {
            r.rows
                .iter()
                .filter(|row| row.threads == most && if raytrail { row.kind.is_raytrail() } else { row.kind.is_peer() })
                .max_by(|a, b| a.mrays_per_s.total_cmp(&b.mrays_per_s))
        };
        if let (Some(ours), Some(peer)) = (best(true), best(false)) {
            outln!(
                "  fastest at {most} thr: raytrail {} {:.2}, peer {} {:.2}: raytrail at {:.2}x the fastest peer",
                ours.target,
                ours.mrays_per_s,
                peer.target,
                peer.mrays_per_s,
                ours.mrays_per_s / peer.mrays_per_s.max(1e-12)
            );
        }
    }
    print_stream_stages(r);
    print_gpu_kernels(r);
    let notes: Vec<String> = r
        .agreement
        .iter()
        .filter(|(_, a)| !a.classes.is_empty())
        .map(|(name, a)| {
            let classes: Vec<String> = a.classes.iter().map(|(c, n)| format!("{n} {}", c.name())).collect();
            format!("{name}: {}", classes.join(", "))
        })
        .collect();
    if !notes.is_empty() {
        outln!("  disagreements with stack: {}", notes.join("; "));
    }
}

/// The stream targets' stages (Garanzha & Loop's Fig. 13) and working figures (their Table 1),
/// measured in the work pass at the most threads.
fn print_stream_stages(r: &RayReport) {
    let rows: Vec<&Row> = {
        let mut seen: Vec<&str> = Vec::new();
        r.rows
            .iter()
            .filter(|row| {
                row.stream.is_some() && !seen.contains(&row.target.as_str()) && {
                    seen.push(&row.target);
                    true
                }
            })
            .collect()
    };
    if rows.is_empty() {
        return;
    }
    outln!(
        "  stream stages, ms (median of 3 runs):  {:>7} {:>9} {:>9} {:>12}  {:>8} {:>8} {:>9} {:>8} {:>9}",
        "sort",
        "frustums",
        "traversal",
        "intersection",
        "packets",
        "rays/pk",
        "leaves/pk",
        "longest",
        "work MB"
    );
    for row in rows {
        let Some(st) = &row.stream else { continue };
        let ms = |s: f64| s * 1e3;
        let per = |x: usize| x as f64 / st.packets.max(1) as f64;
        outln!(
            "  {:<38} {:>7.1} {:>9.1} {:>9.1} {:>12.1}  {:>8} {:>8.1} {:>9.1} {:>8} {:>9.1}",
            row.target,
            ms(st.seconds.sort),
            ms(st.seconds.frustums),
            ms(st.seconds.traversal),
            ms(st.seconds.intersection),
            thousands(st.packets as u64),
            per(r.rays),
            per(st.leaf_refs),
            st.largest_list,
            mb(st.working_bytes)
        );
    }
}

/// The GPU targets' two speeds: end to end (the table's, transfers included) and the kernel alone
/// at steady clocks, with its spread and the bandwidth the transfers took.
fn print_gpu_kernels(r: &RayReport) {
    let mut seen: Vec<&str> = Vec::new();
    let rows: Vec<&Row> = r
        .rows
        .iter()
        .filter(|row| {
            row.kernel.is_some() && !seen.contains(&row.target.as_str()) && {
                seen.push(&row.target);
                true
            }
        })
        .collect();
    if rows.is_empty() {
        return;
    }
    outln!(
        "  GPU Mrays/s:                           {:>10} {:>10} {:>19} {:>9} {:>10}",
        "end to end",
        "kernel",
        "kernel min-max",
        "MB moved",
        "GB/s e2e"
    );
    for row in rows {
        let Some(k) = &row.kernel else { continue };
        let (lo, hi) = k.spread();
        let gbs = if row.median_s > 0.0 { k.bytes_per_trace as f64 / row.median_s / 1e9 } else { 0.0 };
        outln!(
            "  {:<38} {:>10.1} {:>10.1} {:>9.1}-{:<9.1} {:>9.1} {:>10.2}",
            row.target,
            row.mrays_per_s,
            k.median_mrays_per_s(),
            lo,
            hi,
            k.bytes_per_trace as f64 / 1e6,
            gbs
        );
    }
}

/// A per-ray figure, or `-` where not counted.
fn opt(x: Option<f64>) -> String {
    x.map_or("-".to_string(), |x| format!("{x:.1}"))
}

/// `n` with thousands separators.
pub fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The distinct values of `it`, in first-seen order.
fn dedup(it: impl Iterator<Item = usize>) -> Vec<usize> {
    let mut out = Vec::new();
    for x in it {
        if !out.contains(&x) {
            out.push(x);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thousands_separators() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(871_414), "871,414");
        assert_eq!(thousands(1_234_567), "1,234,567");
    }
}
