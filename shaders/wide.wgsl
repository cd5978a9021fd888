// Methods bvh4, bvh8, bvh4-naive, bvh8-sah: a wide BVH collapsed from the binary one (Guthe 2014),
// one state machine for every width (`wide::traverse::WideState`): all children of a node tested,
// the hit ones nearest first by a bitonic sorting network for closest-hit queries and in slot order
// for any-hit queries, all but the first pushed with their entry distances, and a popped child
// dropped when it is entered beyond the closest hit by more than the slack.
//
// Memory (the `kd` binding, words): nodes of 8 * WIDE_W words each (`wide::WideNode`: lo x, y, z,
// hi x, y, z, children, counts; WIDE_W of each), the primitive id of each triangle position from
// `P.kd_prims`, the triangles in leaf order from `P.kd_tris` (nine words each). WIDE_W comes in
// the generated header.

// `wide::traverse::WIDE_STACK`.
const WIDE_STACK: u32 = 448u;
const WIDE_EMPTY: u32 = 0xffffffffu;

// A child: a node index (count 0), or a leaf's first triangle position and count.
struct WideChild {
    child: u32,
    count: u32,
}

struct WideEntry {
    child: u32,
    count: u32,
    t_enter: f32,
}

var<private> WS_CURRENT: WideChild;
var<private> WS_HAS_CURRENT: bool;
var<private> WS_LEN: u32;
var<private> WS_STACK: array<WideEntry, 448>;

// The reference an observer records (`WideChild::node_ref`).
fn wide_ref(c: WideChild) -> u32 {
    return select(c.child, leaf_ref(c.child), c.count != 0u);
}

fn wide_word(node: u32, at: u32) -> u32 {
    return kd[node * 8u * WIDE_W + at];
}

// Slot `i` of node `node` (`WideNode::child_ref`); `ok` false for an empty slot.
struct WideSlot {
    ok: bool,
    c: WideChild,
}

fn wide_slot(node: u32, i: u32) -> WideSlot {
    let child = wide_word(node, 6u * WIDE_W + i);
    let count = wide_word(node, 7u * WIDE_W + i);
    return WideSlot(child != WIDE_EMPTY && i < WIDE_W, WideChild(child, count));
}

// `ChildKernel::test`: each child box by the slab test over the widened interval. WT_ENTER holds
// the entry distances by slot; WT_T and WT_SLOT are the sort keys (`sort_keys`), which the network
// reorders.
var<private> WT_ENTER: array<f32, WIDE_W>;
var<private> WT_T: array<f32, WIDE_W>;
var<private> WT_SLOT: array<u32, WIDE_W>;

fn wide_test(node: u32, lo_t: f32, hi_t: f32) -> u32 {
    var mask = 0u;
    for (var i = 0u; i < WIDE_W; i = i + 1u) {
        let lo = vec3<f32>(bitcast<f32>(wide_word(node, i)), bitcast<f32>(wide_word(node, WIDE_W + i)),
            bitcast<f32>(wide_word(node, 2u * WIDE_W + i)));
        let hi = vec3<f32>(bitcast<f32>(wide_word(node, 3u * WIDE_W + i)),
            bitcast<f32>(wide_word(node, 4u * WIDE_W + i)), bitcast<f32>(wide_word(node, 5u * WIDE_W + i)));
        let h = slab_hit(lo, hi, lo_t, hi_t);
        // `sort_keys`: a missed child sorts after every hit one.
        WT_ENTER[i] = select(bitcast<f32>(0x7f800000u), h.t_enter, h.hit);
        WT_T[i] = WT_ENTER[i];
        WT_SLOT[i] = select(i + WIDE_W, i, h.hit);
        if h.hit {
            mask = mask | (1u << i);
        }
    }
    return mask;
}

// `network::compare_and_swap`: the smaller (key, slot) to lane i, by conditional assignment.
fn wide_cas(i: u32, j: u32) {
    let ki = WT_T[i];
    let kj = WT_T[j];
    let si = WT_SLOT[i];
    let sj = WT_SLOT[j];
    let swap = kj < ki || (kj == ki && sj < si);
    WT_T[i] = select(ki, kj, swap);
    WT_T[j] = select(kj, ki, swap);
    WT_SLOT[i] = select(si, sj, swap);
    WT_SLOT[j] = select(sj, si, swap);
}

// `network::sort_network`: the bitonic network, stage by stage.
fn wide_sort() {
    for (var size = 2u; size <= WIDE_W; size = size * 2u) {
        for (var i = 0u; i < WIDE_W; i = i + 1u) {
            let block = i / size * size;
            let mirror = block + size - 1u - (i - block);
            if i < mirror {
                wide_cas(i, mirror);
            }
        }
        for (var d = size / 4u; d >= 1u; d = d / 2u) {
            for (var i = 0u; i < WIDE_W; i = i + 1u) {
                if (i & d) == 0u && i + d < WIDE_W {
                    wide_cas(i, i + d);
                }
            }
        }
    }
}

// The leaf's triangles; returns whether a hit was taken (an any-hit query stops at its first).
fn wide_leaf(first: u32, count: u32) -> bool {
    var taken = false;
    for (var pos = first; pos < first + count; pos = pos + 1u) {
        let prim = kd[P.kd_prims + pos];
        rec_primitive();
        let o = P.kd_tris + pos * 9u;
        let a = bitcast<vec3<f32>>(vec3<u32>(kd[o], kd[o + 1u], kd[o + 2u]));
        let b = bitcast<vec3<f32>>(vec3<u32>(kd[o + 3u], kd[o + 4u], kd[o + 5u]));
        let c = bitcast<vec3<f32>>(vec3<u32>(kd[o + 6u], kd[o + 7u], kd[o + 8u]));
        let h = tri_intersect(a, b, c, C.tmin, q_limit());
        if h.ok && q_offer(h, prim) {
            taken = true;
            if ANY_HIT {
                return true;
            }
        }
    }
    return taken;
}

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
        WS_CURRENT = WideChild(e.child, e.count);
        return STEP_CONTINUE;
    }
    WS_HAS_CURRENT = false;
    return STEP_DONE;
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
    var n = 0u;
    if ANY_HIT {
        // Unsorted: slot order.
        for (var i = 0u; i < WIDE_W; i = i + 1u) {
            if (mask & (1u << i)) != 0u {
                WT_SLOT[n] = i;
                n = n + 1u;
            }
        }
    } else {
        n = countOneBits(mask);
        wide_sort();
    }
    // All but the first, farthest first.
    for (var k = n - 1u; k >= 1u; k = k - 1u) {
        let slot = WT_SLOT[k] % WIDE_W;
        let s = wide_slot(cur.child, slot);
        if WS_LEN < WIDE_STACK && s.ok {
            WS_STACK[WS_LEN] = WideEntry(s.c.child, s.c.count, WT_ENTER[slot]);
            WS_LEN = WS_LEN + 1u;
        }
    }
    let first = wide_slot(cur.child, WT_SLOT[0] % WIDE_W);
    WS_CURRENT = first.c;
    WS_HAS_CURRENT = first.ok;
    return STEP_CONTINUE;
}

// `trace_wide_batch`'s drive loop: the step always runs once, then the budget is checked.
fn trace(r: Ray) -> Hit {
    if !begin(r) {
        return miss();
    }
    if P.wide_root_count != 0u {
        WS_CURRENT = WideChild(leaf_offset(P.root), P.wide_root_count);
    } else {
        WS_CURRENT = WideChild(P.root, 0u);
    }
    WS_HAS_CURRENT = true;
    WS_LEN = 0u;
    var budget = P.max_steps;
    loop {
        if wide_step() == STEP_DONE || budget == 0u {
            break;
        }
        budget = budget - 1u;
    }
    return Q_HIT;
}
