//! raytrail's methods on the GPU as bench targets (the wgpu backend).

use super::target::{BenchTarget, TargetKind, Work};
use raytrail::core::method::{Method, Query};
use raytrail::core::stream::StreamStats;
use raytrail::core::trace::{Record, Trace, TraceOptions};
use raytrail::core::{Hit, Ray};
use raytrail::gpu::{GpuConfig, KernelTiming, TimingPlan, WgpuBackend, WgpuScene};
use std::sync::Arc;
use std::time::Duration;

/// One method on the GPU. The thread pool does not apply: the GPU traces the whole batch. Its
/// passes are timed end to end by the wall clock (uploads, kernels, read-backs); the kernel alone
/// is timed separately ([`BenchTarget::kernel_timing`]).
pub struct RaytrailGpu {
    method: Method,
    name: String,
    backend: Arc<WgpuBackend>,
    scene: Arc<WgpuScene>,
    timing: TimingPlan,
}

impl RaytrailGpu {
    /// The target tracing `method` over `scene` on `backend`, named `gpu:<method>` for the default
    /// settings and `gpu:<method>/<dispatch>/<workgroup size>` otherwise (a sweep's targets).
    pub fn new(method: Method, backend: Arc<WgpuBackend>, scene: Arc<WgpuScene>, warm_up: Duration) -> Self {
        let name = if *backend.config() == GpuConfig::default() {
            format!("gpu:{}", method.name())
        } else {
            format!("gpu:{}/{}", method.name(), backend.config().label())
        };
        let timing = TimingPlan { warm_up, ..TimingPlan::default() };
        Self { method, name, backend, scene, timing }
    }

    fn run(
        &self,
        rays: &[Ray],
        query: Query,
        hits: &mut [Hit],
        record: Record,
    ) -> Result<raytrail::core::trace::Report, String> {
        let opts = TraceOptions::new(self.method).query(query).record(record);
        self.backend.trace(&self.scene, rays, &opts, hits).map_err(|e| format!("{}: {e}", self.name))
    }
}

impl BenchTarget for RaytrailGpu {
    fn name(&self) -> &str {
        &self.name
    }

    fn kind(&self) -> TargetKind {
        TargetKind::RaytrailGpu
    }

    fn trace(&self, _pool: &rayon::ThreadPool, rays: &[Ray], query: Query, hits: &mut [Hit]) -> Result<(), String> {
        self.run(rays, query, hits, Record::Nothing).map(|_| ())
    }

    fn needs_clock_spin(&self) -> bool {
        true
    }

    fn kernel_timing(&self, rays: &[Ray], query: Query) -> Result<Option<KernelTiming>, String> {
        if !self.backend.has_gpu_timer() || rays.is_empty() {
            return Ok(None);
        }
        let opts = TraceOptions::new(self.method).query(query);
        self.backend
            .time_kernel(&self.scene, rays, &opts, &self.timing)
            .map(Some)
            .map_err(|e| format!("{}: {e}", self.name))
    }

    fn work(&self, _pool: &rayon::ThreadPool, rays: &[Ray], query: Query) -> Result<Option<Work>, String> {
        let mut hits = vec![Hit::MISS; rays.len()];
        let Some(c) = self.run(rays, query, &mut hits, Record::Counters)?.counters else { return Ok(None) };
        let per_ray = |x: u64| Some(x as f64 / c.rays.max(1) as f64);
        Ok(Some(Work { nodes: per_ray(c.nodes()), leaves: per_ray(c.leaves), tests: per_ray(c.primitive_tests) }))
    }

    /// The stream method's stages, from GPU timestamps where the adapter has them (one untimed
    /// pass: the kernels' times vary far less than a shared CPU's).
    fn stream_stats(
        &self,
        _pool: &rayon::ThreadPool,
        rays: &[Ray],
        query: Query,
    ) -> Result<Option<StreamStats>, String> {
        if self.method.stream().is_none() {
            return Ok(None);
        }
        let mut hits = vec![Hit::MISS; rays.len()];
        Ok(self.run(rays, query, &mut hits, Record::Nothing)?.stream)
    }
}
