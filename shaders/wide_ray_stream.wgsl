// Method bvh8-lists: bvh8's tree walked by streams of WIDE_STREAM consecutive rays of the batch
// (`wide::ray_stream`), a stream to a workgroup. Invocation w owns the stream's rays
// 32w .. 32w + 31, one bit each in every ray set, so that it writes its word of a set alone. The
// rule is the core's, step for step:
// - every ray of the current set records the visit and, at a node, tests the children with the
//   single-ray box test over its own interval; per child, the rays that hit it gather into a set
//   and their least entry distance into its key;
// - one invocation orders the hit children as `wide.wgsl` does (the network for closest hits, slot
//   order for any hit) and pushes all but the first (onto a full stack of WS_STACK_SIZE entries,
//   none); a step of its own copies the pushed children's sets to the stream's lists in the scratch
//   and makes the first child's the current set;
// - at a leaf, every ray of the set tests its triangles; an any-hit ray that finds one leaves;
// - a popped entry: every ray of its set still in the stream records a stack pop and visits the
//   child if its entry distance is within its interval. The core keeps each ray's entry distance
//   in the list; here the ray tests the child's box again, whose entry distance does not depend on
//   the interval's end (`slab_hit`), so the lists hold one bit per ray.
// Rays keep nothing between steps but their answer, in `hits`; their constants are made again
// (`begin`) whenever they are visited. Each step is one turn of a loop the whole workgroup runs
// together (its exit read with `workgroupUniformLoad`).
//
// A stream takes at most P.stream_steps steps per dispatch (a round), then saves its state (the
// current set, the stack, where it stands) and counts itself unfinished; the host dispatches
// rounds until none is. On a GPU the steps are unbounded and one round does it; Mesa's lavapipe
// ends an invocation's loops after 65,535 iterations in all (dispatch_persistent.wgsl), fewer
// than a large scene's stream takes. Built on `wide.wgsl` (WT_T, WT_SLOT,
// wide_test, wide_order, wide_push, wide_slot, wide_leaf, wide_ref, wide_root).

// The dispatch override every kernel declares; the workgroup is a stream's WS_WORDS invocations.
override WORKGROUP_SIZE: u32 = 64u;

// Words per set of the stream's rays: one per invocation.
const WS_WORDS: u32 = WIDE_STREAM / 32u;
// `traverse::WIDE_STACK`.
const WS_STACK_SIZE: u32 = (WIDE_W - 1u) * 64u;
const WS_NONE: u32 = 0xffffffffu;
// `order_bits(+inf)`: the key of a child no ray hits.
const WS_KEY_NONE: u32 = 0xff800000u;
// What the current step does: visit WS_CUR, copy the sets of an expanded node, or check which rays
// of a popped entry reach its child.
const WS_VISIT: u32 = 1u;
const WS_COPY: u32 = 2u;
const WS_CHECK: u32 = 3u;

// The slot's kernel scratch, sized by the host: the streams left unfinished by this round, then per
// stream of the batch a region of WS_REGION words: its lists (WS_STACK_SIZE sets of WS_WORDS
// words, set `e` from word `e * WS_WORDS`), then its saved state (`ws_save`).
struct WsScratch {
    unfinished: atomic<u32>,
    pad: array<u32, 3>,
    words: array<u32>,
}

@group(0) @binding(7) var<storage, read_write> ws_scratch: WsScratch;

// Saved state: phase (0: the stream is done), stack length, current child and count, budget,
// the entry being checked and its node and slot (popped, so above the stack's length), then the
// stack (two words an entry), then the current set.
const WS_HEADER: u32 = 8u;
const WS_STATE: u32 = WS_STACK_SIZE * WS_WORDS;
const WS_REGION: u32 = WS_STATE + WS_HEADER + 2u * WS_STACK_SIZE + WS_WORDS;

// A postponed child: its parent node and slot (the ray tests the child's box again on the pop).
struct WsEntry {
    node: u32,
    slot: u32,
}

var<workgroup> WS_STACK: array<WsEntry, WS_STACK_SIZE>;
var<workgroup> WS_LEN: u32;
var<workgroup> WS_CUR: WideChild;
// The expanded node, the slot visited next and each slot's stack entry (WS_NONE: not pushed).
var<workgroup> WS_NODE: u32;
var<workgroup> WS_FIRST: u32;
var<workgroup> WS_PUSHED: array<u32, WIDE_W>;
// The entry being checked.
var<workgroup> WS_ENTRY: u32;
var<workgroup> WS_PHASE: u32;
var<workgroup> WS_GO: u32;
var<workgroup> WS_BUDGET: u32;
// Steps taken this round.
var<workgroup> WS_STEPS: u32;
// The current set, and per child the rays that hit it; word w written by invocation w alone.
var<workgroup> WS_LIVE: array<u32, WS_WORDS>;
var<workgroup> WS_HITS: array<array<u32, WS_WORDS>, WIDE_W>;
// Per child, its least entry distance (`order_bits`); the children hit; whether a check found rays.
var<workgroup> WS_KEYS: array<atomic<u32>, WIDE_W>;
var<workgroup> WS_SEEN: atomic<u32>;
var<workgroup> WS_ANY: atomic<u32>;
var<private> WS_STREAM_INDEX: u32;

// Where set `e`'s word `w` lies in the scratch, and word `i` of the saved state.
fn ws_list_word(e: u32, w: u32) -> u32 {
    return WS_STREAM_INDEX * WS_REGION + e * WS_WORDS + w;
}

fn ws_state_word(i: u32) -> u32 {
    return WS_STREAM_INDEX * WS_REGION + WS_STATE + i;
}

// Makes ray `r` of the stream current: its constants, its answer so far, its records.
fn ws_load(r: u32) -> u32 {
    let slot = WS_STREAM_INDEX * WIDE_STREAM + r;
    rec_select(slot);
    _ = begin(rays[slot]);
    Q_HIT = hits[slot];
    return slot;
}

// Invocation w's part of a visit: its rays of the current set.
fn ws_visit(w: u32) {
    let cur = WS_CUR;
    var rest = WS_LIVE[w];
    var sets: array<u32, WIDE_W>;
    var keys: array<u32, WIDE_W>;
    for (var i = 0u; i < WIDE_W; i = i + 1u) {
        sets[i] = 0u;
        keys[i] = WS_KEY_NONE;
    }
    while rest != 0u {
        let b = countTrailingZeros(rest);
        rest = rest & (rest - 1u);
        let slot = ws_load(w * 32u + b);
        rec_node(wide_ref(cur));
        if cur.count != 0u {
            _ = wide_leaf(cur.child, cur.count);
            hits[slot] = Q_HIT;
            continue;
        }
        let iv = box_interval(q_limit());
        let mask = wide_test(cur.child, iv.x, iv.y);
        for (var i = 0u; i < WIDE_W; i = i + 1u) {
            if (mask & (1u << i)) != 0u {
                sets[i] = sets[i] | (1u << b);
                keys[i] = min(keys[i], order_bits(WT_T[i]));
            }
        }
    }
    if cur.count != 0u {
        return;
    }
    var seen = 0u;
    for (var i = 0u; i < WIDE_W; i = i + 1u) {
        WS_HITS[i][w] = sets[i];
        if sets[i] != 0u {
            seen = seen | (1u << i);
            atomicMin(&WS_KEYS[i], keys[i]);
        }
    }
    if seen != 0u {
        atomicOr(&WS_SEEN, seen);
    }
}

// Invocation w's part of the copy after an expansion.
fn ws_copy(w: u32) {
    for (var i = 0u; i < WIDE_W; i = i + 1u) {
        let e = WS_PUSHED[i];
        if e != WS_NONE {
            ws_scratch.words[ws_list_word(e, w)] = WS_HITS[i][w];
        }
    }
    WS_LIVE[w] = WS_HITS[WS_FIRST % WIDE_W][w];
}

// Invocation w's part of a check: its rays of the popped entry's set.
fn ws_check(w: u32) {
    let e = WS_STACK[WS_ENTRY];
    var rest = ws_scratch.words[ws_list_word(WS_ENTRY, w)];
    var live = 0u;
    while rest != 0u {
        let b = countTrailingZeros(rest);
        rest = rest & (rest - 1u);
        _ = ws_load(w * 32u + b);
        if q_is_answered() {
            continue;
        }
        rec_backtrack(0u, VIA_STACK_POP);
        let iv = box_interval(q_limit());
        // The entry distance as the push saw it: `slab_hit` makes it from the interval's start.
        let t = wide_child_hit(e.node, e.slot % WIDE_W, iv.x, iv.x).t_enter;
        if t <= iv.y {
            live = live | (1u << b);
        }
    }
    WS_LIVE[w] = live;
    if live != 0u {
        atomicOr(&WS_ANY, 1u);
    }
}

// Visits `c` next with the current set, within the step budget.
fn ws_enter(c: WideChild) {
    if WS_BUDGET == 0u {
        WS_GO = 0u;
        return;
    }
    WS_BUDGET = WS_BUDGET - 1u;
    WS_CUR = c;
    WS_PHASE = WS_VISIT;
}

// The next postponed entry, to be checked; none ends the stream.
fn ws_pop() {
    if WS_LEN == 0u {
        WS_GO = 0u;
        return;
    }
    WS_LEN = WS_LEN - 1u;
    WS_ENTRY = WS_LEN;
    WS_PHASE = WS_CHECK;
}

// The leading invocation's part of a step: what comes next, and whether the round ends here (never
// before a copy, so that the sets of the children hit need no saving).
fn ws_lead() {
    ws_next();
    WS_STEPS = WS_STEPS + 1u;
    if WS_GO == 1u && WS_STEPS >= P.stream_steps && WS_PHASE != WS_COPY {
        WS_GO = 2u;
    }
}

fn ws_next() {
    if WS_PHASE == WS_CHECK {
        let any = atomicExchange(&WS_ANY, 0u);
        let e = WS_STACK[WS_ENTRY];
        let s = wide_slot(e.node, e.slot);
        if any != 0u && s.ok {
            ws_enter(s.c);
        } else {
            ws_pop();
        }
        return;
    }
    if WS_PHASE == WS_COPY {
        for (var i = 0u; i < WIDE_W; i = i + 1u) {
            WS_PUSHED[i] = WS_NONE;
        }
        let first = wide_slot(WS_NODE, WS_FIRST);
        if first.ok {
            ws_enter(first.c);
        } else {
            ws_pop();
        }
        return;
    }
    let cur = WS_CUR;
    if cur.count != 0u {
        ws_pop();
        return;
    }
    // `sort_keys` over the stream's keys, as `wide_test` leaves them for one ray.
    let mask = atomicExchange(&WS_SEEN, 0u);
    for (var i = 0u; i < WIDE_W; i = i + 1u) {
        let key = from_order_bits(atomicExchange(&WS_KEYS[i], WS_KEY_NONE));
        let hit = (mask & (1u << i)) != 0u;
        WT_T[i] = select(bitcast<f32>(0x7f800000u), key, hit);
        WT_SLOT[i] = select(i + WIDE_W, i, hit);
    }
    if mask == 0u {
        ws_pop();
        return;
    }
    // As `wide_step`: all hit children but the first pushed, farthest first.
    let first_slot = wide_order(mask);
    let n = countOneBits(mask);
    for (var j = 1u; j < WIDE_W; j = j + 1u) {
        let p = wide_push(WIDE_W - j, mask, first_slot, n);
        if p.push && WS_LEN < WS_STACK_SIZE && wide_slot(cur.child, p.slot).ok {
            WS_STACK[WS_LEN] = WsEntry(cur.child, p.slot);
            WS_PUSHED[p.slot] = WS_LEN;
            WS_LEN = WS_LEN + 1u;
        }
    }
    WS_NODE = cur.child;
    WS_FIRST = first_slot;
    WS_PHASE = WS_COPY;
}

// The first round: every ray of the stream starts as a miss with empty records; the traceable
// ones form the first set.
fn ws_start(w: u32) {
    var live = 0u;
    for (var b = 0u; b < 32u; b = b + 1u) {
        let slot = WS_STREAM_INDEX * WIDE_STREAM + w * 32u + b;
        if slot < P.ray_count {
            rec_begin(slot);
            if begin(rays[slot]) {
                live = live | (1u << b);
            }
            hits[slot] = Q_HIT;
        }
    }
    WS_LIVE[w] = live;
    if w == 0u {
        WS_LEN = 0u;
        WS_BUDGET = P.max_steps;
        WS_PHASE = WS_VISIT;
        WS_CUR = wide_root();
    }
    workgroupBarrier();
    if live != 0u {
        atomicOr(&WS_ANY, 1u);
    }
    workgroupBarrier();
    if w == 0u {
        WS_GO = atomicExchange(&WS_ANY, 0u);
    }
}

// A later round: the state the last one saved.
fn ws_restore(w: u32) {
    WS_LIVE[w] = ws_scratch.words[ws_state_word(WS_HEADER + 2u * WS_STACK_SIZE + w)];
    if w == 0u {
        WS_PHASE = ws_scratch.words[ws_state_word(0u)];
        WS_LEN = ws_scratch.words[ws_state_word(1u)];
        WS_CUR = WideChild(ws_scratch.words[ws_state_word(2u)], ws_scratch.words[ws_state_word(3u)]);
        WS_BUDGET = ws_scratch.words[ws_state_word(4u)];
        WS_ENTRY = ws_scratch.words[ws_state_word(5u)];
        WS_GO = select(1u, 0u, WS_PHASE == 0u);
    }
    workgroupBarrier();
    let len = WS_LEN;
    for (var e = w; e < len; e = e + WS_WORDS) {
        let at = ws_state_word(WS_HEADER + 2u * e);
        WS_STACK[e] = WsEntry(ws_scratch.words[at], ws_scratch.words[at + 1u]);
    }
    if w == 0u && WS_PHASE == WS_CHECK {
        WS_STACK[WS_ENTRY] = WsEntry(ws_scratch.words[ws_state_word(6u)], ws_scratch.words[ws_state_word(7u)]);
    }
}

// Saves the state at the end of a round (phase 0 once the stream is done); an unfinished stream
// counts itself.
fn ws_save(w: u32, finished: bool) {
    if finished {
        if w == 0u {
            ws_scratch.words[ws_state_word(0u)] = 0u;
        }
        return;
    }
    ws_scratch.words[ws_state_word(WS_HEADER + 2u * WS_STACK_SIZE + w)] = WS_LIVE[w];
    let len = WS_LEN;
    for (var e = w; e < len; e = e + WS_WORDS) {
        let at = ws_state_word(WS_HEADER + 2u * e);
        ws_scratch.words[at] = WS_STACK[e].node;
        ws_scratch.words[at + 1u] = WS_STACK[e].slot;
    }
    if w == 0u {
        ws_scratch.words[ws_state_word(0u)] = WS_PHASE;
        ws_scratch.words[ws_state_word(1u)] = len;
        ws_scratch.words[ws_state_word(2u)] = WS_CUR.child;
        ws_scratch.words[ws_state_word(3u)] = WS_CUR.count;
        ws_scratch.words[ws_state_word(4u)] = WS_BUDGET;
        ws_scratch.words[ws_state_word(5u)] = WS_ENTRY;
        if WS_PHASE == WS_CHECK {
            ws_scratch.words[ws_state_word(6u)] = WS_STACK[WS_ENTRY].node;
            ws_scratch.words[ws_state_word(7u)] = WS_STACK[WS_ENTRY].slot;
        }
        atomicAdd(&ws_scratch.unfinished, 1u);
    }
}

@compute @workgroup_size(WS_WORDS)
fn main(
    @builtin(local_invocation_index) w: u32,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    WS_STREAM_INDEX = wid.x + wid.y * groups.x;
    if WS_STREAM_INDEX * WIDE_STREAM >= P.ray_count {
        return;
    }
    if w < WIDE_W {
        atomicStore(&WS_KEYS[w], WS_KEY_NONE);
        WS_PUSHED[w] = WS_NONE;
    }
    if w == 0u {
        atomicStore(&WS_SEEN, 0u);
        atomicStore(&WS_ANY, 0u);
        WS_STEPS = 0u;
    }
    if P.stream_round == 0u {
        ws_start(w);
    } else {
        ws_restore(w);
    }
    loop {
        if workgroupUniformLoad(&WS_GO) != 1u {
            break;
        }
        let phase = WS_PHASE;
        if phase == WS_VISIT {
            ws_visit(w);
        } else if phase == WS_COPY {
            ws_copy(w);
        } else {
            ws_check(w);
        }
        workgroupBarrier();
        if w == 0u {
            ws_lead();
        }
    }
    ws_save(w, workgroupUniformLoad(&WS_GO) == 0u);
}
