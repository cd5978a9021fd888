//! What `auto` does with a large batch in no useful order whose rays are slow to trace: it sorts
//! it ([`TraceOrder::for_batch`]) and traces it with one walk, without timing candidates.

use super::choice::{Portion, SampleClock};
use super::sample::{sample, CpuClock};
use raytrail_core::method::{Method, Query, WideMethod};
use raytrail_core::trace_order::TraceOrder;
use raytrail_core::{Error, Ray};
use raytrail_cpu::{CpuBackend, CpuScene};

/// The walk `auto` traces a sorted batch with: packets of the 8-wide tree of least node area.
/// Sorted, a batch's neighbouring rays start close together in one octant, which is what packets
/// need. On shuffled diffuse and ambient-occlusion rays inside Sponza, the kitchen and the full
/// dragon it was the fastest sorted walk on four of six sets and within 5% of it on the others,
/// while timing candidates on a sample of the unsorted batch picked single rays, up to 38% slower
/// once sorted, and cost 3-18% of a trace (`docs/notes/*-sorted-trace-order.md`, "The table").
pub const SORTED_WALK: Method = Method::Wide(WideMethod::BVH8_SAH_PACKET);

/// The walk a sample is timed with to tell whether its batch is slow enough to sort.
pub const PROBE_WALK: Method = Method::Wide(WideMethod::BVH8_SAH);

/// Seconds per ray and thread, on the sample traced as given by [`PROBE_WALK`], from which `auto`
/// sorts a batch: sorting costs about 25 ns a ray on two threads and gains 10-40% of the trace,
/// so it pays only on slow rays. Shuffled ambient-occlusion rays onto Sponza from outside (30-60
/// ns a ray and thread) ran at 0.43 of the fastest method sorted; the interiors' diffuse rays
/// (300-400 ns) gained 1.1-1.3 (`docs/notes/*-sorted-trace-order.md`, "Which batches to sort").
pub const SORT_FROM_SECONDS_PER_RAY: f64 = 100e-9;

/// The method `auto` traces `rays` with where their order decides it: [`SORTED_WALK`] for a batch
/// it sorts (large, in no useful order, and slow per ray on a sample), `None` for one it traces as
/// given (its method is then chosen by timing candidates); with the seconds the sample's timing
/// cost. `scene` must hold [`PROBE_WALK`]'s tree for a batch [`TraceOrder::for_batch`] would sort.
pub fn sorted_walk(
    backend: &CpuBackend,
    scene: &CpuScene,
    rays: &[Ray],
    query: Query,
) -> Result<(Option<Method>, f64), Error> {
    if TraceOrder::for_batch(rays) != TraceOrder::Sorted {
        return Ok((None, 0.0));
    }
    let sample = sample(rays);
    let mut clock = CpuClock::new(backend, scene, &sample, query);
    // The first trace starts the pool's workers; the second is the one judged.
    let warm = clock.seconds(PROBE_WALK, Portion::Whole)?;
    let seconds = clock.seconds(PROBE_WALK, Portion::Whole)?;
    let per_ray = seconds * backend.threads() as f64 / sample.len().max(1) as f64;
    Ok(((per_ray >= SORT_FROM_SECONDS_PER_RAY).then_some(SORTED_WALK), warm + seconds))
}
