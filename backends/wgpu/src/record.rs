//! Reading back what the kernels recorded (shaders/record.wgsl).

use raytrail_core::observe::Counters;

/// Counters per ray, in the order of shaders/record.wgsl.
pub(crate) const COUNTERS: usize = 22;

/// Words per ray: the event count, the counters, then `cap` node references.
pub(crate) fn stride(cap: usize) -> usize {
    1 + COUNTERS + cap
}

/// Adds one ray's recorded counters to `total`.
pub(crate) fn add_counters(total: &mut Counters, slot: &[u32]) {
    let c = |i: usize| u64::from(slot[1 + i]);
    total.internal_nodes += c(0);
    total.leaves += c(1);
    total.primitive_tests += c(2);
    total.backtracks += c(3);
    total.stack_pops += c(4);
    for i in 0..4 {
        total.register[i] += c(5 + i);
    }
    for i in 0..2 {
        total.hash[i] += c(9 + i);
    }
    total.iterative += c(11);
    total.link_reads += c(12);
    total.restarts += c(13);
    for i in 0..8 {
        total.levels[i] += c(14 + i);
    }
}

/// One ray's node references, or `None` when they overflowed the slot's capacity.
pub(crate) fn node_refs(slot: &[u32], cap: usize) -> Option<&[u32]> {
    let n = slot[0] as usize;
    (n <= cap).then(|| &slot[1 + COUNTERS..1 + COUNTERS + n])
}
