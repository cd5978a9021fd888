//! The main job's GPU part: the same rays and methods on the wgpu backend, timed, and checked
//! against the CPU ray by ray.

use raytrail::core::method::{Method, Query};
use raytrail::core::nearest::NearestPoint;
use raytrail::core::prepared::PreparedScene;
use raytrail::core::trace::{Trace, TraceOptions};
use raytrail::core::{Hit, Ray};
use raytrail::cpu::{CpuBackend, CpuScene};
use raytrail::gpu::{WgpuBackend, WgpuScene};
use raytrail::{AllHits, AllHitsOptions};
use raytrail_conformance::check::{check_against, Context, Mismatch};
use std::sync::Arc;
use std::time::Instant;

/// Median seconds of a method's GPU passes.
#[derive(Clone, Copy, Debug)]
pub struct GpuTimes {
    /// The whole call: uploads, kernels, read-backs.
    pub end_to_end: f64,
    /// The kernels alone (GPU timestamps), where the adapter has them.
    pub kernel: Option<f64>,
}

/// The GPU side of a run, when there is an adapter.
pub struct Gpu {
    backend: WgpuBackend,
    scene: WgpuScene,
}

impl Gpu {
    /// Opens the adapter and uploads the scene, or says in one line why the GPU part is skipped.
    pub fn open(prepared: Arc<PreparedScene>) -> Result<Gpu, String> {
        let backend = WgpuBackend::new().map_err(|e| e.to_string())?;
        let scene = backend.prepare(prepared).map_err(|e| e.to_string())?;
        Ok(Gpu { backend, scene })
    }

    /// The adapter, the timer used, and what its compiler does to float arithmetic.
    pub fn describe(&self) -> String {
        let timer = if self.backend.has_gpu_timer() {
            "end to end by the wall clock, kernels alone by GPU timestamps"
        } else {
            "end to end by the wall clock (no timestamp queries for the kernels alone)"
        };
        let probe = match self.backend.probe_numerics(1 << 16) {
            Ok(p) => p.summary(),
            Err(e) => format!("numerics probe failed: {e}"),
        };
        format!("{}; timed by {timer}\n  numerics probe: {probe}", self.backend.adapter())
    }

    /// Median seconds of `passes` timed traces (after one untimed pass that compiles the kernel):
    /// end to end (uploads, kernels, read-backs), and the kernels alone where the adapter has
    /// timestamps.
    pub fn time(&self, rays: &[Ray], method: Method, query: Query, passes: usize) -> Result<GpuTimes, String> {
        let opts = TraceOptions::new(method).query(query);
        let mut hits = vec![Hit::MISS; rays.len()];
        self.backend.trace(&self.scene, rays, &opts, &mut hits).map_err(|e| e.to_string())?;
        let (mut wall, mut kernel) = (Vec::with_capacity(passes), Vec::with_capacity(passes));
        for _ in 0..passes {
            let r = self.backend.trace(&self.scene, rays, &opts, &mut hits).map_err(|e| e.to_string())?;
            wall.push(r.seconds);
            kernel.extend(r.kernel_seconds);
        }
        let kernel = (kernel.len() == wall.len() && !kernel.is_empty()).then(|| crate::median::median(&kernel));
        Ok(GpuTimes { end_to_end: crate::median::median(&wall), kernel })
    }

    /// Traces `rays` once with `method` (`raytrail render --backend gpu`).
    pub fn trace(&self, rays: &[Ray], method: Method, query: Query, hits: &mut [Hit]) -> Result<(), String> {
        let opts = TraceOptions::new(method).query(query);
        self.backend.trace(&self.scene, rays, &opts, hits).map(|_| ()).map_err(|e| e.to_string())
    }

    /// Every method on `rays` on the GPU: against its reference there, and against the CPU.
    pub fn check(
        &self,
        cpu: &CpuBackend,
        cpu_scene: &CpuScene,
        ctx: Context<'_>,
        rays: &[Ray],
    ) -> Result<Vec<Mismatch>, String> {
        check_against(cpu, cpu_scene, &self.backend, &self.scene, ctx, rays, &Method::ALL).map_err(|e| e.to_string())
    }

    /// Every hit along each of `rays` on the GPU, after an untimed call that compiles the kernel;
    /// with the timed call's seconds.
    pub fn all_hits(&self, rays: &[Ray], options: &AllHitsOptions) -> Result<(AllHits, f64), String> {
        self.backend.all_hits(&self.scene, &rays[..rays.len().min(1)], options).map_err(|e| e.to_string())?;
        let start = Instant::now();
        let lists = self.backend.all_hits(&self.scene, rays, options).map_err(|e| e.to_string())?;
        Ok((lists, start.elapsed().as_secs_f64()))
    }

    /// The nearest point to each of `points` on the GPU, after an untimed call that compiles the
    /// kernel; with the timed call's seconds.
    pub fn nearest_points(&self, points: &[[f32; 3]], radius: f32) -> Result<(Vec<Option<NearestPoint>>, f64), String> {
        self.backend.nearest_points(&self.scene, &points[..points.len().min(1)], radius).map_err(|e| e.to_string())?;
        let start = Instant::now();
        let found = self.backend.nearest_points(&self.scene, points, radius).map_err(|e| e.to_string())?;
        Ok((found, start.elapsed().as_secs_f64()))
    }
}
