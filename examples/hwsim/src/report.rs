//! Plain-text tables comparing methods.

use crate::memory::{Table, LINE_BYTES};
use crate::sim::{CycleRecord, MethodReport};
use raytrail_core::method::WideMethod;
use raytrail_core::method::WideWalk;
use raytrail_core::prepared::PreparedScene;
use std::fmt::Write as _;

/// Columns padded to their widest cell, text left-aligned, numbers right-aligned.
fn render(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut widths: Vec<usize> = header.iter().map(|h| h.len()).collect();
    for row in rows {
        for (w, c) in widths.iter_mut().zip(row) {
            *w = (*w).max(c.len());
        }
    }
    let mut s = String::new();
    let line = |s: &mut String, cells: &mut dyn Iterator<Item = &str>| {
        for (i, (c, w)) in cells.zip(&widths).enumerate() {
            let sep = if i == 0 { "" } else { "  " };
            if i == 0 {
                let _ = write!(s, "{sep}{c:<w$}");
            } else {
                let _ = write!(s, "{sep}{c:>w$}");
            }
        }
        s.push('\n');
    };
    line(&mut s, &mut header.iter().copied());
    let total: usize = widths.iter().sum::<usize>() + 2 * (widths.len() - 1);
    s.push_str(&"-".repeat(total));
    s.push('\n');
    for row in rows {
        line(&mut s, &mut row.iter().map(String::as_str));
    }
    s
}

fn f(v: f64, digits: usize) -> String {
    format!("{v:.digits$}")
}

/// The lockstep table: cycles, SIMT efficiency, transitions and state per method.
pub fn lockstep_table(reports: &[MethodReport]) -> String {
    let header = [
        "method",
        "state B",
        "cycles/warp",
        "latency/warp",
        "SIMT eff",
        "diverg",
        "steps/ray",
        "inner/ray",
        "leaf/ray",
        "pop/ray",
        "reg/ray",
        "hash/ray",
        "walk/ray",
        "restart/ray",
        "stack B/ray",
        "peak stack",
        "dep rd/ray",
        "chain max",
    ];
    let rows: Vec<Vec<String>> = reports
        .iter()
        .map(|r| {
            let t = &r.transitions;
            let stack = r.stack_bytes_per_ray();
            vec![
                r.method.name().to_string(),
                r.state_bytes.to_string(),
                f(r.cycles_per_warp(), 1),
                f(r.latency_cycles_per_warp(), 1),
                format!("{:.1}%", 100.0 * r.simt_efficiency()),
                format!("{:.0}%", 100.0 * r.divergent_cycles as f64 / r.cycles.max(1) as f64),
                f(r.per_ray(r.lane_steps), 2),
                f(r.per_ray(t.internal), 2),
                f(r.per_ray(t.leaf), 2),
                f(r.per_ray(t.stack_pop), 2),
                f(r.per_ray(t.register), 2),
                f(r.per_ray(t.hash), 2),
                f(r.per_ray(t.iterative), 2),
                f(r.per_ray(t.restart), 2),
                stack.map_or("-".to_string(), |b| f(b, 1)),
                if stack.is_some() { r.peak_stack.to_string() } else { "-".to_string() },
                f(r.dependent_reads_per_ray(), 2),
                r.max_chain.to_string(),
            ]
        })
        .collect();
    render(&header, &rows)
}

/// The memory table: bytes per ray by table (the tables some report read), reads per ray, and
/// cache lines per ray and per warp-step.
pub fn memory_table(reports: &[MethodReport]) -> String {
    let tables: Vec<Table> =
        Table::ALL.into_iter().filter(|&t| reports.iter().any(|r| r.traffic.bytes(t) > 0)).collect();
    let names: Vec<String> = tables.iter().map(|t| format!("{} B/ray", t.name())).collect();
    let mut header = vec!["method"];
    header.extend(names.iter().map(String::as_str));
    header.extend(["total B/ray", "reads/ray", "lines/ray", "lines/step", "B/line"]);
    let rows: Vec<Vec<String>> = reports
        .iter()
        .map(|r| {
            let tr = &r.traffic;
            let mut row = vec![r.method.name().to_string()];
            row.extend(tables.iter().map(|&t| f(r.per_ray(tr.bytes(t)), 1)));
            row.push(f(r.per_ray(tr.total_bytes()), 1));
            row.push(f(r.per_ray(tr.total_reads()), 2));
            row.push(f(r.per_ray(tr.lines), 2));
            row.push(f(tr.lines as f64 / r.cycles.max(1) as f64, 2));
            // Bytes the lanes asked for per line fetched: above 64, lanes share lines.
            row.push(f(tr.total_bytes() as f64 / tr.lines.max(1) as f64, 1));
            row
        })
        .collect();
    render(&header, &rows)
}

/// Both tables with a legend.
pub fn tables(reports: &[MethodReport]) -> String {
    let warp = reports.first().map_or(0, |r| r.warp);
    let mut s = String::new();
    let _ = writeln!(s, "Lockstep, {warp} lanes per warp (per-ray figures are means over rays):");
    s.push_str(&lockstep_table(reports));
    s.push_str(
        "  state B: per-ray traversal registers (Method::state_bytes); cycles: one transition per lane per cycle;\n  \
         latency: cycles if each dependent read of a step (node, each link of a walk, each hash table) took one\n  \
         and a warp waited for its slowest lane (stack and register taken as on-chip: a pop costs no read);\n  \
         SIMT eff: mean active lanes / warp width; diverg: cycles mixing internal-node and leaf steps;\n  \
         inner/leaf: node steps; pop/reg/hash/walk/restart: backtracking steps served by stack pop, register,\n  \
         perfect hash, walk over links, restart (kd); stack B: entries pushed + popped (BVH2 4 B, kd 12 B,\n  \
         wide 8 B); peak stack: most entries live in one ray; dep rd: dependent reads per ray (the sum of\n  \
         each step's chain: node, each link, each hash table; a kd leaf's node, references, triangles);\n  \
         chain max: the longest chain in one step.\n\n",
    );
    let _ = writeln!(
        s,
        "Memory traffic ({LINE_BYTES}-byte lines; records: BVH2 node 64 B, leaf word 16 B, hash entries 4 B, kd node 8 B,\n\
         reference 4 B, triangle 36 B, wide node 32 W B, block of four triangles 144 B, primitive id 4 B):"
    );
    s.push_str(&memory_table(reports));
    s.push_str(
        "  lines/ray: distinct lines per warp-step, summed, per ray; lines/step: distinct lines one warp-step\n  \
         touches (all lanes together); B/line: bytes requested per line fetched (above 64: lanes share lines).\n",
    );
    s
}

/// The trees' sizes: what each structure keeps in memory for the same scene (triangles stored in
/// the BVH2 leaf words, beside the kd-tree, and in the wide trees' blocks).
pub fn structures(p: &PreparedScene) -> String {
    let mut s = String::new();
    if let Some(l) = p.uncles.as_ref() {
        let _ = write!(
            s,
            "trees: BVH2 {} nodes x 64 B = {} B (+ leaf words {} B)",
            l.nodes.len(),
            l.nodes.len() * 64,
            l.leaves.len() * 16
        );
    }
    if let Some(kd) = p.kd.as_ref() {
        let st = kd.tree.stats();
        let _ = write!(
            s,
            "; kd {} nodes x 8 B = {} B (+ references {} B), depth {}",
            kd.tree.nodes().len(),
            kd.tree.nodes().len() * 8,
            kd.tree.prims().len() * 4,
            st.depth
        );
    }
    // The packet method walks bvh8's tree, the keyed one bvh4's.
    for m in WideMethod::ALL.into_iter().filter(|m| m.walk() == WideWalk::Stack) {
        if let Ok(t) = p.wide_tree(m) {
            let st = t.stats();
            let w = m.width();
            let _ = write!(s, "; {m} {} nodes x {} B = {} B, depth {}", st.nodes, 32 * w, st.nodes * 32 * w, st.depth);
        }
    }
    s
}

/// One warp's cycles as rows of lane symbols (see [`crate::Transition::symbol`]).
pub fn timeline(cycles: &[CycleRecord]) -> String {
    let mut s = String::new();
    for (i, c) in cycles.iter().enumerate() {
        let lanes: String = c.lanes.iter().map(|t| t.symbol()).collect();
        let _ = writeln!(s, "{i:>5}  {lanes}  {:>2} active, {:>3} lines, {} rounds", c.active, c.lines, c.rounds);
    }
    s
}
