// Methods bvh4, bvh8, bvh4-naive, bvh8-sah: a wide BVH collapsed from the binary one (Guthe 2014),
// one state machine for every width (`wide::traverse::WideState`): all children of a node tested,
// the hit ones nearest first by a bitonic sorting network for closest-hit queries and in slot order
// for any-hit queries, all but the first pushed with their entry distances, and a popped child
// dropped when it is entered beyond the closest hit by more than the slack. The node layout, box
// tests, order and leaf test are wide.wgsl's.

// Stack entries: `W - 1` postponed children on each of 64 levels, the bound behind
// `wide::traverse::WIDE_STACK` (which holds the 8-wide case for every width). Sized by the width
// here because a private array this large lives in local memory, and a 4-wide kernel needs less
// than half of it; a tree never fills either, so both push exactly the CPU's entries.
const WIDE_STACK: u32 = (WIDE_W - 1u) * 64u;

// An entry is 8 bytes: where the postponed child lies in the node memory (`wide_child_word`) and
// its entry distance. The pop reads the child back from the node; the stack, in local memory,
// moves two thirds of the bytes of an entry holding child and count. On an H200 that made every
// wide stack kernel 1.01-1.45x faster (the figure is in commit 1baaac0's message; no note has its table).
struct WideEntry {
    word: u32,
    t_enter: f32,
}

var<private> WS_CURRENT: WideChild;
var<private> WS_HAS_CURRENT: bool;
var<private> WS_LEN: u32;
var<private> WS_STACK: array<WideEntry, WIDE_STACK>;

// `WideState::pop`.
fn wide_pop() -> u32 {
    loop {
        if WS_LEN == 0u {
            break;
        }
        WS_LEN = WS_LEN - 1u;
        let e = WS_STACK[WS_LEN];
        rec_backtrack(0u, VIA_STACK_POP);
        if e.t_enter > q_limit() + C.t_slack {
            continue;
        }
        WS_CURRENT = wide_child_at(e.word);
        return STEP_CONTINUE;
    }
    WS_HAS_CURRENT = false;
    return STEP_DONE;
}

// Push `k` of a node's expansion (`wide_push`), if it is one.
fn wide_stack_push(node: u32, k: u32, mask: u32, first_slot: u32, n: u32) {
    let p = wide_push(k, mask, first_slot, n);
    if p.push && WS_LEN < WIDE_STACK {
        let word = wide_child_word(node, p.slot);
        // The slot's emptiness alone, not `wide_slot`: the count is read back at the pop.
        if wide_slot_ok(p.slot, kd[word]) {
            WS_STACK[WS_LEN] = WideEntry(word, WT_T[k]);
            WS_LEN = WS_LEN + 1u;
        }
    }
}

// `WideState::step`.
fn wide_step() -> u32 {
    if !WS_HAS_CURRENT {
        return STEP_DONE;
    }
    let cur = WS_CURRENT;
    rec_node(wide_ref(cur));
    if cur.count != 0u {
        wide_leaf(cur.child, cur.count);
        if q_is_answered() {
            return STEP_DONE;
        }
        return wide_pop();
    }
    let iv = box_interval(q_limit());
    let mask = wide_test(cur.child, iv.x, iv.y);
    if mask == 0u {
        return wide_pop();
    }
    // All hit children but the first pushed, farthest first: for a closest-hit query by rank
    // after the network, for an any-hit query in descending slot order (unsorted, Sec. 4.2).
    // A miss sorts after every hit, so rank k < n is a hit. Slot 0 is never pushed: when hit, it
    // is the first. Written out for 4-wide nodes, a loop for 8-wide ones, as `wide_test` is.
    let first_slot = wide_order(mask);
    let n = countOneBits(mask);
    if WIDE_W == 4u {
        wide_stack_push(cur.child, 3u, mask, first_slot, n);
        wide_stack_push(cur.child, 2u, mask, first_slot, n);
        wide_stack_push(cur.child, 1u, mask, first_slot, n);
    } else {
        for (var j = 1u; j < WIDE_W; j = j + 1u) {
            wide_stack_push(cur.child, WIDE_W - j, mask, first_slot, n);
        }
    }
    let first = wide_slot(cur.child, first_slot);
    WS_CURRENT = first.c;
    WS_HAS_CURRENT = first.ok;
    return STEP_CONTINUE;
}

// `WideState::run` from `c`: the step always runs once, then the budget is checked.
fn wide_run(c: WideChild) {
    WS_CURRENT = c;
    WS_HAS_CURRENT = true;
    WS_LEN = 0u;
    var budget = P.max_steps;
    loop {
        if wide_step() == STEP_DONE || budget == 0u {
            break;
        }
        budget = budget - 1u;
    }
}

// `trace_wide_batch`'s drive loop.
fn trace(r: Ray) -> Hit {
    if !begin(r) {
        return miss();
    }
    wide_run(wide_root());
    return Q_HIT;
}
