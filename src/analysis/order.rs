//! What `auto` does with a batch in no useful order: it sorts it ([`TraceOrder::for_batch`]) and
//! traces it with one walk, without timing candidates.

use raytrail_core::method::{Method, WideMethod};
use raytrail_core::trace_order::TraceOrder;
use raytrail_core::Ray;

/// The walk `auto` traces a sorted batch with: packets of the 8-wide tree of least node area.
/// Sorted, a batch's neighbouring rays start close together in one octant, which is what packets
/// need. On shuffled diffuse and ambient-occlusion rays inside Sponza, the kitchen and the full
/// dragon it was the fastest sorted walk on four of six sets and within 5% of it on the others,
/// while timing candidates on a sample of the unsorted batch picked single rays, up to 38% slower
/// once sorted, and cost 3-18% of a trace (`docs/notes/*-sorted-trace-order.md`, "The table").
pub const SORTED_WALK: Method = Method::Wide(WideMethod::BVH8_SAH_PACKET);

/// The method `auto` traces `rays` with where their order decides it: [`SORTED_WALK`] for a batch
/// it sorts, `None` for one traced as given (its method is chosen by timing candidates).
pub fn sorted_walk(rays: &[Ray]) -> Option<Method> {
    (TraceOrder::for_batch(rays) == TraceOrder::Sorted).then_some(SORTED_WALK)
}
