// Recording, compiled away unless the pipeline's RECORD override asks for it
// (`observe::{Counters, Recorder}`). Each ray owns `P.record_stride` words of `records`:
//   [0]            node events seen (may exceed the capacity: the overflow flag),
//   [1 ..= 22]     counters, in `Counters` order (see backends/wgpu/src/record.rs),
//   [23 ..]        up to `P.record_cap` node references, in visiting order.

const REC_COUNTERS: u32 = 22u;
const C_INTERNAL: u32 = 0u;
const C_LEAVES: u32 = 1u;
const C_PRIMS: u32 = 2u;
const C_BACKTRACKS: u32 = 3u;
const C_STACK_POPS: u32 = 4u;
const C_REGISTER: u32 = 5u;
const C_HASH: u32 = 9u;
const C_ITERATIVE: u32 = 11u;
const C_LINK_READS: u32 = 12u;
const C_RESTARTS: u32 = 13u;
const C_LEVELS: u32 = 14u;

// How a backtracking step found its target (`observe::Backtrack`).
const VIA_STACK_POP: u32 = 0u;
// Register sources: postponed, uncle, grand uncle, grand-grand uncle (add the source).
const VIA_REGISTER: u32 = 1u;
// Hash: not direct, direct (add 1 when direct).
const VIA_HASH: u32 = 5u;
const VIA_ITERATIVE: u32 = 7u;
const VIA_RESTART: u32 = 8u;

var<private> REC_BASE: u32;

fn rec_begin(ray: u32) {
    if RECORD == 0u {
        return;
    }
    REC_BASE = ray * P.record_stride;
    for (var i = 0u; i <= REC_COUNTERS; i = i + 1u) {
        records[REC_BASE + i] = 0u;
    }
}

// Points recording at another ray's slots without clearing them (packets trace several rays).
fn rec_select(ray: u32) {
    if RECORD == 0u {
        return;
    }
    REC_BASE = ray * P.record_stride;
}

fn rec_count(counter: u32) {
    if RECORD == 0u {
        return;
    }
    let at = REC_BASE + 1u + counter;
    records[at] = records[at] + 1u;
}

// `Observer::node`.
fn rec_node(r: u32) {
    if RECORD == 0u {
        return;
    }
    rec_count(select(C_INTERNAL, C_LEAVES, is_leaf(r)));
    if RECORD == 2u {
        let n = records[REC_BASE];
        if n < P.record_cap {
            records[REC_BASE + 1u + REC_COUNTERS + n] = r;
        }
        records[REC_BASE] = n + 1u;
    }
}

// `Observer::primitive`.
fn rec_primitive() {
    rec_count(C_PRIMS);
}

// `Observer::backtrack`: `via` is a VIA_* constant (plus the register source or hash directness).
fn rec_backtrack(levels: u32, via: u32) {
    if RECORD == 0u {
        return;
    }
    rec_count(C_BACKTRACKS);
    rec_count(C_LEVELS + min(levels, 7u));
    if via == VIA_STACK_POP {
        rec_count(C_STACK_POPS);
    } else if via < VIA_HASH {
        rec_count(C_REGISTER + via - VIA_REGISTER);
    } else if via < VIA_ITERATIVE {
        rec_count(C_HASH + via - VIA_HASH);
    } else if via == VIA_ITERATIVE {
        rec_count(C_ITERATIVE);
    } else {
        rec_count(C_RESTARTS);
    }
}

// `Observer::link_read`.
fn rec_link_read() {
    rec_count(C_LINK_READS);
}
