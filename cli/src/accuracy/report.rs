//! What `raytrail accuracy` measured (written as JSON as it is), the Pareto front, and the table.

use super::classify::Tally;
use serde::Serialize;

/// A whole run.
#[derive(Clone, Debug, Serialize)]
pub struct AccuracyReport {
    /// The command as given.
    pub command: String,
    /// Most rays per ray set judged against the exact reference.
    pub sample: usize,
    /// Timed passes per row.
    pub passes: usize,
    /// Threads of the pool that traced.
    pub threads: usize,
    /// Primary image width.
    pub width: u32,
    /// Primary image height.
    pub height: u32,
    /// The verdict's tolerance `delta`, in multiples of `2^-24` of the scene's largest coordinate.
    pub tolerance_ulps: f64,
    /// The default method.
    pub default_method: String,
    /// The default triangle test.
    pub default_test: String,
    /// One entry per scene and view.
    pub scenes: Vec<SceneReport>,
}

/// One scene seen from one view.
#[derive(Clone, Debug, Serialize)]
pub struct SceneReport {
    /// File name, with " (inside)" for the inside view.
    pub name: String,
    /// Triangles.
    pub triangles: usize,
    /// One entry per ray set.
    pub rays: Vec<RaySetReport>,
}

/// One ray set.
#[derive(Clone, Debug, Serialize)]
pub struct RaySetReport {
    /// Ray type.
    pub kind: String,
    /// `closest` or `any`.
    pub query: String,
    /// Rays traced (and timed).
    pub rays: usize,
    /// Rays judged against the exact reference.
    pub sampled: usize,
    /// One row per method and triangle test.
    pub rows: Vec<Row>,
}

/// One method with one triangle test on one ray set.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Method name.
    pub method: String,
    /// Triangle test name.
    pub test: String,
    /// Millions of rays per second: the median pass.
    pub mrays_per_s: f64,
    /// Seconds of every timed pass.
    pub passes_s: Vec<f64>,
    /// Wrong answers as a share of the sample.
    pub error_rate: f64,
    /// The judged sample.
    #[serde(flatten)]
    pub tally: Tally,
    /// Whether no other row is at least as fast with at most as many errors (and better in one).
    pub pareto: bool,
    /// Whether this is the default method with the default test.
    pub default: bool,
}

/// Marks the rows on the Pareto front of speed (higher is better) against error rate (lower).
pub fn mark_pareto(rows: &mut [Row]) {
    let points: Vec<(f64, f64)> = rows.iter().map(|r| (r.mrays_per_s, r.error_rate)).collect();
    for (i, r) in rows.iter_mut().enumerate() {
        let (s, e) = points[i];
        r.pareto = !points.iter().enumerate().any(|(j, &(s2, e2))| j != i && s2 >= s && e2 <= e && (s2 > s || e2 < e));
    }
}

/// Prints one scene's tables on standard output.
pub fn print_scene(s: &SceneReport) {
    outln!("\n{} ({} triangles)", s.name, s.triangles);
    for r in &s.rays {
        outln!(
            "  {} rays ({} hit): {} traced, {} judged against the exact reference; * on the Pareto front, \
             (d) the default",
            r.kind,
            r.query,
            r.rays,
            r.sampled
        );
        outln!(
            "    {:<16} {:<16} {:>8} {:>7} {:>5} {:>7} {:>6} {:>6} {:>6} {:>6} {:>8} {:>9} {:>8}",
            "method",
            "test",
            "Mrays/s",
            "exact",
            "near",
            "refused",
            "f.miss",
            "f.hit",
            "wrong",
            "bad t",
            "error %",
            "t ulp max",
            "t ulp mean"
        );
        for row in &r.rows {
            let t = &row.tally;
            outln!(
                "    {:<16} {:<16} {:>8.2} {:>7} {:>5} {:>7} {:>6} {:>6} {:>6} {:>6} {:>8.3} {:>9.2} {:>8.3} {}{}",
                row.method,
                row.test,
                row.mrays_per_s,
                t.exact,
                t.near,
                t.refused,
                t.false_misses,
                t.false_hits,
                t.wrong_prims,
                t.bad_t,
                100.0 * row.error_rate,
                t.t_ulps_max,
                t.t_ulps_mean,
                if row.pareto { "*" } else { "" },
                if row.default { " (d)" } else { "" },
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(speed: f64, err: f64) -> Row {
        Row {
            method: String::new(),
            test: String::new(),
            mrays_per_s: speed,
            passes_s: vec![],
            error_rate: err,
            tally: Tally::default(),
            pareto: false,
            default: false,
        }
    }

    #[test]
    fn the_front_keeps_only_undominated_rows() {
        let mut rows = vec![row(1.0, 0.0), row(2.0, 0.0), row(3.0, 0.01), row(2.5, 0.02), row(2.0, 0.0), row(0.5, 0.5)];
        mark_pareto(&mut rows);
        // Equal points do not dominate each other; a slower, wronger one is dominated.
        assert_eq!(rows.iter().map(|r| r.pareto).collect::<Vec<_>>(), [false, true, true, false, true, false]);
    }
}
