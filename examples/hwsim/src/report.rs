//! Plain-text tables comparing methods.

use crate::memory::{Table, LINE_BYTES};
use crate::sim::{CycleRecord, MethodReport};
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
        "stack B/ray",
        "peak stack",
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
                stack.map_or("-".to_string(), |b| f(b, 1)),
                if stack.is_some() { r.peak_stack.to_string() } else { "-".to_string() },
            ]
        })
        .collect();
    render(&header, &rows)
}

/// The memory table: reads and bytes per ray by table, and cache lines per warp-step.
pub fn memory_table(reports: &[MethodReport]) -> String {
    let header = [
        "method",
        "node B/ray",
        "leaf B/ray",
        "disp B/ray",
        "cell B/ray",
        "total B/ray",
        "reads/ray",
        "lines/step",
        "B/line",
    ];
    let rows: Vec<Vec<String>> = reports
        .iter()
        .map(|r| {
            let tr = &r.traffic;
            let mut row = vec![r.method.name().to_string()];
            row.extend(Table::ALL.iter().map(|&t| f(r.per_ray(tr.bytes(t)), 1)));
            row.push(f(r.per_ray(tr.total_bytes()), 1));
            row.push(f(r.per_ray(tr.total_reads()), 2));
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
         inner/leaf: node steps; pop/reg/hash/walk: backtracking steps served by stack pop, register, perfect\n  \
         hash, walk over links; stack B: 4-byte entries pushed + popped; peak stack: most entries live in one ray.\n\n",
    );
    let _ =
        writeln!(s, "Memory traffic ({LINE_BYTES}-byte lines; records: node 64 B, leaf word 16 B, hash entries 4 B):");
    s.push_str(&memory_table(reports));
    s.push_str(
        "  lines/step: distinct lines one warp-step touches (all lanes together); B/line: bytes requested per line\n  \
         fetched (above 64: lanes share lines).\n",
    );
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
