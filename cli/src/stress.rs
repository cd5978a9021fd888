//! `raytrail stress`: the numerics stress suite as a report. Every case (rays at shared vertices and
//! edges, grazing and axis-parallel rays, far origins, scaled, translated and subnormal scenes,
//! tiny triangles beside huge ones, the edges of the supported range) with every method, each ray
//! judged against the exact reference; per case and method: rays, agreeing, refused, disagreeing.

use crate::args::StressArgs;
use crate::failure::{Failure, Outcome};
use crate::progress::Progress;
use raytrail::core::method::Method;
use raytrail::core::trace::Trace;
use raytrail::cpu::CpuBackend;
use raytrail::gpu::WgpuBackend;
use raytrail_conformance::stress::{all_cases, run_case, Tally};

/// Runs the suite on the CPU and, unless `--no-gpu` or without an adapter, on the GPU; exit
/// status 1 when any ray disagrees with the exact reference.
pub fn main(a: StressArgs) -> Outcome {
    let cases = all_cases().map_err(|e| Failure::Run(e.to_string()))?;
    let cpu = CpuBackend::new();
    let gpu = if a.no_gpu {
        outln!("GPU: skipped (--no-gpu)");
        None
    } else {
        match WgpuBackend::new() {
            Ok(b) => {
                outln!("GPU: {}", b.adapter());
                Some(b)
            }
            Err(e) => {
                outln!("GPU: skipped ({e})");
                None
            }
        }
    };
    let backends = 1 + usize::from(gpu.is_some());
    let mut progress = Progress::new("stress cases", cases.len() * backends);
    let mut results: Vec<(String, &'static str, Vec<Tally>)> = Vec::new();
    for case in &cases {
        results.push((case.name.clone(), "cpu", run_case(&cpu, case).map_err(|e| Failure::Run(e.to_string()))?));
        progress.step(&format!("{} on the CPU", case.name));
        if let Some(g) = &gpu {
            results.push((case.name.clone(), "wgpu", run_case(g, case).map_err(|e| Failure::Run(e.to_string()))?));
            progress.step(&format!("{} on the GPU", case.name));
        }
    }
    progress.finish();
    Ok(print(&results, cpu.name()))
}

/// Prints one line per case and backend (the methods summed) and every method that disagrees;
/// returns the exit status.
fn print(results: &[(String, &'static str, Vec<Tally>)], cpu_name: &str) -> i32 {
    outln!(
        "\n{:<44} {:<5} {:>8} {:>9} {:>8} {:>8} {:>10}",
        "case",
        "on",
        "rays",
        "agree",
        "near",
        "refused",
        "disagree"
    );
    let mut bad = Vec::new();
    for (case, backend, tallies) in results {
        let sum = |f: fn(&Tally) -> usize| tallies.iter().map(f).sum::<usize>();
        outln!(
            "{case:<44} {backend:<5} {:>8} {:>9} {:>8} {:>8} {:>10}",
            sum(|t| t.rays),
            sum(Tally::agreeing),
            sum(|t| t.near),
            sum(|t| t.refused),
            sum(|t| t.disagreeing)
        );
        bad.extend(tallies.iter().filter(|t| t.disagreeing > 0).map(|t| format!("  {case} on {backend}: {t}")));
    }
    outln!("(each row sums the {} methods; {cpu_name} and wgpu trace the same rays)", Method::ALL.len());
    if bad.is_empty() {
        outln!("\nstress: every ray agrees with the exact reference or is refused where the range allows it.");
        0
    } else {
        outln!("\nSTRESS FAILED: {} method and case pairs disagree with the exact reference:", bad.len());
        for b in &bad {
            outln!("{b}");
        }
        1
    }
}
