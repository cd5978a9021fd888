//! The `auto` bench target: per batch (and thread count), the method `--method auto` chooses by
//! timing the candidates on a sample of the batch, then that method.
//!
//! The choice is made on the first trace of a batch, the untimed warm-up, so the timed passes
//! measure the chosen method alone; what choosing costs is kept and printed with the choice
//! (`docs/notes/*-benchmarks-auto.md`, "`auto` against every fixed method", weighs it against the
//! batch's trace time).

use super::target::{BenchTarget, RaytrailCpu, TargetKind, Work};
use raytrail::analysis::choice::Choice;
use raytrail::analysis::order::sorted_walk;
use raytrail::analysis::sample::choose_on_cpu;
use raytrail::core::method::{Method, Query};
use raytrail::core::trace_order::TraceOrder;
use raytrail::core::{Hit, Ray};
use raytrail::cpu::{CpuBackend, CpuScene};
use std::sync::{Arc, Mutex};

/// Which batch a choice was made for: its rays' address and length, the query and the pool's
/// thread count (the bench keeps each batch in place while it measures it).
type BatchKey = (usize, usize, Query, usize);

/// The `auto` target.
pub struct AutoTarget {
    scene: CpuScene,
    backend: CpuBackend,
    chosen: Mutex<Option<(BatchKey, Method, TraceOrder)>>,
    fixed: Mutex<Option<(Method, TraceOrder, Arc<RaytrailCpu>)>>,
    /// Every choice made, in order, with the batch's length (shared with the caller, who prints
    /// them).
    pub choices: Arc<Mutex<Vec<(usize, Choice)>>>,
}

impl AutoTarget {
    /// The target over `scene`, which must hold the candidates' tables.
    pub fn new(scene: CpuScene) -> Self {
        AutoTarget {
            scene,
            backend: CpuBackend::new(),
            chosen: Mutex::new(None),
            fixed: Mutex::new(None),
            choices: Arc::default(),
        }
    }

    /// The method and order for this batch: the ones chosen before, or a new choice.
    fn method(&self, pool: &rayon::ThreadPool, rays: &[Ray], query: Query) -> Result<(Method, TraceOrder), String> {
        let key = (rays.as_ptr() as usize, rays.len(), query, pool.current_num_threads());
        let mut chosen = self.chosen.lock().map_err(|_| "auto: a trace panicked".to_string())?;
        if let Some((k, m, o)) = *chosen {
            if k == key {
                return Ok((m, o));
            }
        }
        let (choice, order) = pool
            .install(|| match sorted_walk(&self.backend, &self.scene, rays, query)? {
                // A batch `auto` sorts goes to one walk; its cost is the sample's timing.
                (Some(method), cost_seconds) => {
                    Ok((Choice { method, timed: Vec::new(), cost_seconds, lists: None }, TraceOrder::Sorted))
                }
                (None, probe) => choose_on_cpu(&self.backend, &self.scene, rays, query).map(|mut c| {
                    c.cost_seconds += probe;
                    (c, TraceOrder::AsGiven)
                }),
            })
            .map_err(|e| format!("auto: {e}"))?;
        let m = choice.method;
        *chosen = Some((key, m, order));
        self.choices.lock().map_err(|_| "auto: a trace panicked".to_string())?.push((rays.len(), choice));
        Ok((m, order))
    }

    /// The fixed-method target of the method chosen for this batch, in the order `auto` traces
    /// it in. Kept from one pass to the next, with its sort buffers.
    fn fixed(&self, pool: &rayon::ThreadPool, rays: &[Ray], query: Query) -> Result<Arc<RaytrailCpu>, String> {
        let (method, order) = self.method(pool, rays, query)?;
        let mut fixed = self.fixed.lock().map_err(|_| "auto: a trace panicked".to_string())?;
        match &*fixed {
            Some((m, o, target)) if (*m, *o) == (method, order) => Ok(target.clone()),
            _ => {
                let target = Arc::new(RaytrailCpu::new(method, self.scene.clone()).in_order(order));
                *fixed = Some((method, order, target.clone()));
                Ok(target)
            }
        }
    }
}

impl BenchTarget for AutoTarget {
    fn name(&self) -> &str {
        crate::flags::AUTO
    }

    fn kind(&self) -> TargetKind {
        TargetKind::RaytrailAuto
    }

    fn trace(&self, pool: &rayon::ThreadPool, rays: &[Ray], query: Query, hits: &mut [Hit]) -> Result<(), String> {
        self.fixed(pool, rays, query)?.trace(pool, rays, query, hits)
    }

    fn work(&self, pool: &rayon::ThreadPool, rays: &[Ray], query: Query) -> Result<Option<Work>, String> {
        self.fixed(pool, rays, query)?.work(pool, rays, query)
    }
}
