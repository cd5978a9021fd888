// Method kd-packet: the packetized short-stack traversal of Horn et al. 2007, A.5, with push-down
// (`kd::traverse::trace_kd_packet::<4>` as the CPU backend calls it). One invocation traces a
// packet of four consecutive rays of the batch, which the host has grouped by direction octant
// as the CPU does (core/src/traverse/packets.rs), so they share every node's child order.
//
// The packet descends where any live lane's segment goes; each lane stays live only where its own
// segment goes and restarts from the exit of the last leaf it was live in, so it visits exactly
// the leaves it would alone. Lane i is bit i of the `u32` masks and component i of the vectors.
// Each lane keeps its own ray constants and answer in PK_C, PK_TR and PK_HIT; `lane_load` moves
// them into the shared `C`, `TR` and `Q_HIT` that kd_common.wgsl works on, and points recording
// at the lane's ray.
//
// The per-lane work of a step is written out lane by lane rather than as a loop: Mesa's llvmpipe
// (lavapipe, the CI adapter) cuts every loop short once a group of invocations has run 65535 loop
// iterations in all (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS), and lane loops made each step cost
// five iterations instead of one.

// PACKET_WIDTH (rays per packet) comes in the generated header.
const ALL_LANES: u32 = 0xfu;

// One entry of the packet's short stack: a node and every lane's segment and liveness there.
struct PacketEntry {
    node: u32,
    t_min: vec4<f32>,
    t_max: vec4<f32>,
    live: u32,
}

var<private> PK_C: array<Ctx, 4>;
var<private> PK_TR: array<TriRay, 4>;
var<private> PK_HIT: array<Hit, 4>;
var<private> PK_STACK: array<PacketEntry, SHORT_STACK_MAX>;
// The packet's first ray, its node, and every lane's segment and state.
var<private> PK_BASE: u32;
var<private> PK_NODE: u32;
var<private> PK_T_MIN: vec4<f32>;
var<private> PK_T_MAX: vec4<f32>;
var<private> PK_SCENE_MAX: vec4<f32>;
// Where each lane resumes after a restart: the exit of the last leaf it was live in.
var<private> PK_RESUME: vec4<f32>;
var<private> PK_LIVE: u32;
var<private> PK_DONE: u32;
// Short-stack depth, and the push-down restart point (`pushing`: the descent since the last
// restart has entered one child at every node).
var<private> PK_LEN: u32;
var<private> PK_RESTART_AT: u32;
var<private> PK_PUSHING: bool;
// How the live lanes cross the current inner node (PK_SPLIT: for lanes entering both children).
var<private> PK_WANT_FIRST: u32;
var<private> PK_WANT_SECOND: u32;
var<private> PK_SPLIT: vec4<f32>;
var<private> PK_FIRST_CHILD: u32;
var<private> PK_SECOND_CHILD: u32;

fn lane(i: u32) -> u32 {
    return 1u << i;
}

// The lanes of a mask as a vector, for `select`.
fn lanes(mask: u32) -> vec4<bool> {
    return (vec4<u32>(mask) & vec4<u32>(1u, 2u, 4u, 8u)) != vec4<u32>(0u);
}

fn lane_load(i: u32) {
    C = PK_C[i];
    TR = PK_TR[i];
    Q_HIT = PK_HIT[i];
    rec_select(PK_BASE + i);
}

// Lane i meets inner node `n`, if live.
fn cross_lane(i: u32, n: vec2<u32>) {
    if (PK_LIVE & lane(i)) == 0u {
        return;
    }
    lane_load(i);
    rec_node(PK_NODE);
    let c = kd_cross(n, PK_T_MIN[i], PK_T_MAX[i]);
    if c.kind != CROSS_SECOND {
        PK_WANT_FIRST = PK_WANT_FIRST | lane(i);
        PK_FIRST_CHILD = c.first;
    }
    if c.kind != CROSS_FIRST {
        PK_WANT_SECOND = PK_WANT_SECOND | lane(i);
        PK_SECOND_CHILD = c.second;
    }
    if c.kind == CROSS_BOTH {
        PK_SPLIT[i] = c.t_split;
    }
}

// Lane i tests leaf `n`, if live; it is done at its early exit or at the scene's end.
fn leaf_lane(i: u32, n: vec2<u32>) {
    if (PK_LIVE & lane(i)) == 0u {
        return;
    }
    lane_load(i);
    if kd_leaf(PK_NODE, n, PK_T_MAX[i]) || PK_T_MAX[i] >= PK_SCENE_MAX[i] {
        PK_DONE = PK_DONE | lane(i);
    }
    PK_HIT[i] = Q_HIT;
    PK_RESUME[i] = PK_T_MAX[i];
}

fn backtrack_lane(i: u32, via: u32) {
    if (PK_LIVE & lane(i)) != 0u {
        rec_select(PK_BASE + i);
        rec_backtrack(0u, via);
    }
}

// `Observer::backtrack` for every live lane.
fn backtrack_lanes(via: u32) {
    if RECORD == 0u {
        return;
    }
    backtrack_lane(0u, via);
    backtrack_lane(1u, via);
    backtrack_lane(2u, via);
    backtrack_lane(3u, via);
}

// One iteration of `trace_kd_packet`'s loop.
fn packet_step(capacity: u32) {
    let n = kd_node(PK_NODE);
    // A popped entry may hold no lane that is still unfinished: go straight to the next one.
    if PK_LIVE != 0u && !kd_is_leaf(n) {
        PK_WANT_FIRST = 0u;
        PK_WANT_SECOND = 0u;
        cross_lane(0u, n);
        cross_lane(1u, n);
        cross_lane(2u, n);
        cross_lane(3u, n);
        if PK_WANT_SECOND == 0u || PK_WANT_FIRST == 0u {
            PK_NODE = select(PK_SECOND_CHILD, PK_FIRST_CHILD, PK_WANT_SECOND == 0u);
            if PK_PUSHING {
                PK_RESTART_AT = PK_NODE;
            }
            return;
        }
        PK_PUSHING = false;
        // Lanes entering both children take the far part with the entry and keep the near part.
        let both = lanes(PK_WANT_FIRST & PK_WANT_SECOND);
        let e = PacketEntry(PK_SECOND_CHILD, select(PK_T_MIN, PK_SPLIT, both), PK_T_MAX, PK_WANT_SECOND);
        PK_T_MAX = select(PK_T_MAX, PK_SPLIT, both);
        if capacity > 0u {
            if PK_LEN == capacity {
                // Full: the bottom entry is dropped; a restart will find it.
                for (var k = 1u; k < PK_LEN; k = k + 1u) {
                    PK_STACK[k - 1u] = PK_STACK[k];
                }
                PK_LEN = PK_LEN - 1u;
            }
            PK_STACK[PK_LEN] = e;
            PK_LEN = PK_LEN + 1u;
        }
        PK_LIVE = PK_WANT_FIRST;
        PK_NODE = PK_FIRST_CHILD;
        return;
    }
    if kd_is_leaf(n) {
        leaf_lane(0u, n);
        leaf_lane(1u, n);
        leaf_lane(2u, n);
        leaf_lane(3u, n);
    }
    if PK_LEN > 0u {
        PK_LEN = PK_LEN - 1u;
        let e = PK_STACK[PK_LEN];
        PK_NODE = e.node;
        PK_T_MIN = e.t_min;
        PK_T_MAX = e.t_max;
        PK_LIVE = e.live & ~PK_DONE;
        backtrack_lanes(VIA_STACK_POP);
        PK_PUSHING = false;
        return;
    }
    // Stack empty: restart every unfinished lane from where its last leaf ended.
    PK_NODE = PK_RESTART_AT;
    PK_PUSHING = true;
    PK_LIVE = ~PK_DONE & ALL_LANES;
    PK_T_MIN = select(PK_T_MIN, PK_RESUME, lanes(PK_LIVE));
    PK_T_MAX = select(PK_T_MAX, PK_SCENE_MAX, lanes(PK_LIVE));
    backtrack_lanes(VIA_RESTART);
}

// Traces rays `base .. base + n` (n <= 4; lanes from n on stay done, like the CPU's short packet).
fn trace_packet(base: u32, n: u32) {
    // Everything a packet reads starts from zero, as private memory does when an invocation
    // starts: with persistent threads one invocation traces many packets, and a lane without a
    // traceable ray copies `C` and `TR` as they were.
    C = Ctx();
    TR = TriRay();
    PK_C = array<Ctx, 4>();
    PK_TR = array<TriRay, 4>();
    PK_HIT = array<Hit, 4>();
    PK_STACK = array<PacketEntry, SHORT_STACK_MAX>();
    PK_RESUME = vec4<f32>(0.0);
    PK_WANT_FIRST = 0u;
    PK_WANT_SECOND = 0u;
    PK_SPLIT = vec4<f32>(0.0);
    PK_FIRST_CHILD = 0u;
    PK_SECOND_CHILD = 0u;
    PK_BASE = base;
    PK_T_MIN = vec4<f32>(0.0);
    PK_T_MAX = vec4<f32>(0.0);
    PK_SCENE_MAX = vec4<f32>(0.0);
    PK_DONE = ALL_LANES;
    for (var i = 0u; i < n; i = i + 1u) {
        rec_begin(base + i);
        if begin(rays[base + i]) {
            let s = scene_interval();
            if s.hit {
                PK_T_MIN[i] = s.t_enter;
                PK_T_MAX[i] = s.t_exit;
                PK_SCENE_MAX[i] = s.t_exit;
                PK_DONE = PK_DONE & ~lane(i);
            }
        }
        PK_C[i] = C;
        PK_TR[i] = TR;
        PK_HIT[i] = Q_HIT;
    }
    let capacity = min(P.short_stack, SHORT_STACK_MAX);
    PK_LIVE = ~PK_DONE & ALL_LANES;
    PK_RESUME = PK_T_MIN;
    PK_LEN = 0u;
    PK_NODE = 0u;
    PK_RESTART_AT = 0u;
    PK_PUSHING = true;
    // `max_steps * 4`, saturating.
    var budget = select(P.max_steps * PACKET_WIDTH, 0xffffffffu, P.max_steps > 0xffffffffu / PACKET_WIDTH);
    loop {
        if PK_DONE == ALL_LANES || budget == 0u {
            break;
        }
        budget = budget - 1u;
        packet_step(capacity);
    }
    for (var i = 0u; i < n; i = i + 1u) {
        hits[base + i] = PK_HIT[i];
    }
}

// Work items of the packet kernel: item `p` is packet p, rays 4p .. 4p + 3 of the batch (as
// `entry.wgsl` is for the one-ray kernels; a dispatch file hands out the items).
fn item_count() -> u32 {
    return (P.ray_count + PACKET_WIDTH - 1u) / PACKET_WIDTH;
}

fn run_item(p: u32) {
    let base = p * PACKET_WIDTH;
    trace_packet(base, min(PACKET_WIDTH, P.ray_count - base));
}
