// Detects a device that cut the kernel's loops short (the loop limiter in backends/wgpu/NUMERICS.md).
// Mesa's llvmpipe counts the loop iterations a SIMD group of invocations runs, every loop of the
// shader against one limit of 65,535, and past it ends each loop after its current iteration
// without a word: a walk stops halfway and its ray reports a miss. A loop that must run twice then
// runs once, so each kernel runs such a loop when all its work is done and raises `loops_cut`,
// which the host reads back with the hits: it traces the batch again with one item per SIMD group,
// or fails the trace, rather than return them.

struct DispatchState {
    // dispatch_persistent.wgsl's item counter.
    next_item: atomic<u32>,
    // Nonzero once an invocation found its loops cut short.
    loops_cut: atomic<u32>,
}

@group(0) @binding(7) var<storage, read_write> dispatch_state: DispatchState;

// Whether this invocation's loops have been cut short: a loop of two iterations ran only one. The
// bound reads `P.zero` so that no compiler can unroll the loop away.
fn loops_were_cut() -> bool {
    var runs = 0u;
    loop {
        runs = runs + 1u;
        if runs >= 2u + P.zero {
            break;
        }
    }
    return runs < 2u;
}

// Raises the dispatch's `loops_cut` flag if this invocation's loops were cut short.
fn guard_loops() {
    if loops_were_cut() {
        atomicMax(&dispatch_state.loops_cut, 1u);
    }
}

// Invocations per work item: 1, or `P.item_spread` when the host traces a batch again with one
// item per SIMD group of invocations (lavapipe's groups are at most 16 wide), so that no group
// runs the loops of several long items.
fn item_spread() -> u32 {
    return max(P.item_spread, 1u);
}
