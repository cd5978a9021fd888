//! What a bench run found: per scene, its builds and memory, and per ray type a row per target and
//! thread count, with hit agreement against raytrail's stack method.

use super::agreement::Agreement;
use super::rays::RayKind;
use super::target::{TargetKind, Work};
use super::view::View;
use raytrail::core::stream::StreamStats;
use raytrail::gpu::KernelTiming;

/// One build step: what was built, how long it took, and the memory it holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Built {
    /// What was built, by whom.
    pub what: String,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Bytes held, by part.
    pub bytes: Vec<(String, usize)>,
}

/// One target at one thread count on one ray type.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Target name.
    pub target: String,
    /// Target group.
    pub kind: TargetKind,
    /// Threads traced with.
    pub threads: usize,
    /// Seconds of each timed pass, in the order run.
    pub passes: Vec<f64>,
    /// Median of `passes`.
    pub median_s: f64,
    /// Millions of rays per second at the median.
    pub mrays_per_s: f64,
    /// Speed relative to the baseline at the same thread count (> 1: faster).
    pub ratio: Option<f64>,
    /// Work per ray, where counted.
    pub work: Option<Work>,
    /// A stream method's stages and working figures (from the work pass).
    pub stream: Option<StreamStats>,
    /// A GPU target's kernel time at steady clocks (the row's own speed is end to end: uploads,
    /// kernels and read-backs of every pass).
    pub kernel: Option<KernelTiming>,
}

/// Every row for one ray type of one scene.
#[derive(Clone, Debug, PartialEq)]
pub struct RayReport {
    /// Ray type.
    pub kind: RayKind,
    /// Number of rays.
    pub rays: usize,
    /// Rows, by thread count then target order.
    pub rows: Vec<Row>,
    /// Agreement of each target's hits with the stack method's, in target order.
    pub agreement: Vec<(String, Agreement)>,
}

/// Everything measured on one scene.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneReport {
    /// Scene name (file name; " (inside)" added for the inside view).
    pub name: String,
    /// Where the camera stood.
    pub view: View,
    /// Triangles.
    pub triangles: usize,
    /// Primary image size.
    pub width: u32,
    /// Primary image size.
    pub height: u32,
    /// Build steps, raytrail's then the peers'.
    pub builds: Vec<Built>,
    /// Per ray type.
    pub rays: Vec<RayReport>,
}

/// A whole run.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchReport {
    /// The command line, for the record.
    pub command: String,
    /// Baseline target name.
    pub baseline: String,
    /// Timed passes per measurement.
    pub passes: usize,
    /// Thread counts measured.
    pub threads: Vec<usize>,
    /// Per scene.
    pub scenes: Vec<SceneReport>,
}

/// Megabytes (2^20 bytes).
pub fn mb(bytes: usize) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}
