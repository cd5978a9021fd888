// Method bvh8-packet: bvh8's tree walked by packets of WIDE_PACKET rays of one direction octant
// (`wide::packet`), a packet to a workgroup and a ray to an invocation. The host arranges the batch
// into the core's packets (padding as untraceable rays), so workgroup p traces slots
// `WIDE_PACKET * p ..`; loop_guard.wgsl follows this file. The rule is the core's, step for step:
// - every ray of the current mask records the visit and, at a node, tests the children with the
//   single-ray box test over its own interval; per child, the rays that hit it gather into a mask
//   and their least entry distance into its key (workgroup atomics);
// - one invocation orders the hit children as `wide.wgsl` does (the network for closest hits, slot
//   order for any hit), visits the first and pushes the others with their masks and keys;
// - at a leaf, every ray of the mask tests its triangles; an any-hit ray that finds one leaves;
// - a popped entry keeps its rays still in the packet (each records a stack pop) whose interval
//   reaches the key, checked by the rays themselves in a step of their own;
// - a child to be visited by at most WIDE_HAND_OVER rays is handed over: each of them traverses
//   its subtree alone with `wide_stack.wgsl`'s single-ray loop (a step of its own), then the
//   packet pops its next entry.
// Each step is one turn of a loop that the whole workgroup runs together (its exit is read with
// `workgroupUniformLoad`), so the barriers stay in uniform control flow. Built on `wide.wgsl`
// (WT_T, WT_SLOT, wide_test, wide_order, wide_push, wide_slot, wide_leaf, wide_ref) and
// `wide_stack.wgsl` (wide_run).

// The dispatch override every kernel declares; the workgroup is a packet here.
override WORKGROUP_SIZE: u32 = 64u;

const WP_STACK_SIZE: u32 = (WIDE_W - 1u) * 64u;
// `order_bits(+inf)`: the key of a child no ray hits.
const WP_KEY_NONE: u32 = 0xff800000u;
// What the current step does: visit WP_CUR, or check which rays of a popped entry reach it.
const WP_VISIT: u32 = 1u;
const WP_CHECK: u32 = 2u;
// Or hand WP_CUR over to its rays.
const WP_ALONE: u32 = 3u;

// A child with its rays and key (the current one, or a postponed one).
struct WpEntry {
    child: u32,
    count: u32,
    rays: u32,
    key: f32,
}

var<workgroup> WP_STACK: array<WpEntry, WP_STACK_SIZE>;
var<workgroup> WP_LEN: u32;
var<workgroup> WP_CUR: WpEntry;
var<workgroup> WP_PHASE: u32;
var<workgroup> WP_GO: u32;
var<workgroup> WP_BUDGET: u32;
var<workgroup> WP_ACTIVE: atomic<u32>;
var<workgroup> WP_LIVE: atomic<u32>;
var<workgroup> WP_HITS: array<atomic<u32>, WIDE_W>;
var<workgroup> WP_KEYS: array<atomic<u32>, WIDE_W>;
// Each ray's box interval end (`limit + slack`), kept by the ray.
var<workgroup> WP_T_HI: array<f32, WIDE_PACKET>;
// The leading invocation's copy of the rays per hit slot.
var<private> WP_RAYS: array<u32, WIDE_W>;

// After a ray's leaf test or handed-over subtree (`each_alone`): an answered ray leaves the
// packet, the others narrow their box interval to their closest hit.
fn wp_after_alone(lane: u32) {
    if q_is_answered() {
        atomicAnd(&WP_ACTIVE, ~(1u << lane));
    } else {
        WP_T_HI[lane] = box_interval(q_limit()).y;
    }
}

// One ray's part of a step.
fn wp_lane(lane: u32) {
    let cur = WP_CUR;
    let bit = 1u << lane;
    if (cur.rays & bit) == 0u {
        return;
    }
    if WP_PHASE == WP_CHECK {
        rec_backtrack(0u, VIA_STACK_POP);
        if cur.key <= WP_T_HI[lane] {
            atomicOr(&WP_LIVE, bit);
        }
        return;
    }
    if WP_PHASE == WP_ALONE {
        wide_run(WideChild(cur.child, cur.count));
        wp_after_alone(lane);
        return;
    }
    rec_node(wide_ref(WideChild(cur.child, cur.count)));
    if cur.count != 0u {
        wide_leaf(cur.child, cur.count);
        wp_after_alone(lane);
        return;
    }
    let iv = box_interval(q_limit());
    let mask = wide_test(cur.child, iv.x, iv.y);
    for (var i = 0u; i < WIDE_W; i = i + 1u) {
        if (mask & (1u << i)) != 0u {
            atomicOr(&WP_HITS[i], bit);
            atomicMin(&WP_KEYS[i], order_bits(WT_T[i]));
        }
    }
}

// Visits `c` with `rays` next, within the step budget.
fn wp_enter(c: WideChild, rays: u32, key: f32) {
    if WP_BUDGET == 0u || atomicLoad(&WP_ACTIVE) == 0u {
        WP_GO = 0u;
        return;
    }
    WP_BUDGET = WP_BUDGET - 1u;
    WP_CUR = WpEntry(c.child, c.count, rays, key);
    WP_PHASE = wp_visit_phase(rays);
}

// Visited by the packet, or handed over to its rays when they are few.
fn wp_visit_phase(rays: u32) -> u32 {
    return select(WP_VISIT, WP_ALONE, countOneBits(rays) <= WIDE_HAND_OVER);
}

// The next postponed entry with rays still in the packet, to be checked; none ends the packet.
fn wp_pop() {
    let in_packet = atomicLoad(&WP_ACTIVE);
    loop {
        if WP_LEN == 0u || in_packet == 0u {
            WP_GO = 0u;
            return;
        }
        WP_LEN = WP_LEN - 1u;
        let e = WP_STACK[WP_LEN];
        let rays = e.rays & in_packet;
        if rays != 0u {
            WP_CUR = WpEntry(e.child, e.count, rays, e.key);
            WP_PHASE = WP_CHECK;
            return;
        }
    }
}

// The leading invocation's part of a step: what comes next.
fn wp_lead() {
    let cur = WP_CUR;
    if WP_PHASE == WP_ALONE {
        wp_pop();
        return;
    }
    if WP_PHASE == WP_CHECK {
        let live = atomicLoad(&WP_LIVE);
        atomicStore(&WP_LIVE, 0u);
        if live != 0u {
            wp_enter(WideChild(cur.child, cur.count), live, cur.key);
        } else {
            wp_pop();
        }
        return;
    }
    if cur.count != 0u {
        wp_pop();
        return;
    }
    // `sort_keys` over the packet's keys, as `wide_test` leaves them for one ray.
    var mask = 0u;
    for (var i = 0u; i < WIDE_W; i = i + 1u) {
        let rays = atomicLoad(&WP_HITS[i]);
        let key = from_order_bits(atomicLoad(&WP_KEYS[i]));
        atomicStore(&WP_HITS[i], 0u);
        atomicStore(&WP_KEYS[i], WP_KEY_NONE);
        WP_RAYS[i] = rays;
        WT_T[i] = select(bitcast<f32>(0x7f800000u), key, rays != 0u);
        WT_SLOT[i] = select(i + WIDE_W, i, rays != 0u);
        if rays != 0u {
            mask = mask | (1u << i);
        }
    }
    if mask == 0u {
        wp_pop();
        return;
    }
    // As `wide_step`: all hit children but the first pushed, farthest first.
    let first_slot = wide_order(mask);
    let n = countOneBits(mask);
    for (var j = 1u; j < WIDE_W; j = j + 1u) {
        let k = WIDE_W - j;
        let p = wide_push(k, mask, first_slot, n);
        let slot = p.slot;
        if p.push && WP_LEN < WP_STACK_SIZE {
            let s = wide_slot(cur.child, slot);
            if s.ok {
                WP_STACK[WP_LEN] = WpEntry(s.c.child, s.c.count, WP_RAYS[slot], WT_T[k]);
                WP_LEN = WP_LEN + 1u;
            }
        }
    }
    let first = wide_slot(cur.child, first_slot);
    if first.ok {
        wp_enter(first.c, WP_RAYS[first_slot], WT_T[0]);
    } else {
        wp_pop();
    }
}

@compute @workgroup_size(WIDE_PACKET)
fn main(
    @builtin(local_invocation_index) lane: u32,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let slot = (wid.x + wid.y * groups.x) * WIDE_PACKET + lane;
    let have = slot < P.ray_count;
    var mine = false;
    if have {
        rec_begin(slot);
        mine = begin(rays[slot]);
    }
    if lane < WIDE_W {
        atomicStore(&WP_HITS[lane], 0u);
        atomicStore(&WP_KEYS[lane], WP_KEY_NONE);
    }
    if lane == 0u {
        atomicStore(&WP_ACTIVE, 0u);
        atomicStore(&WP_LIVE, 0u);
        WP_LEN = 0u;
        WP_BUDGET = P.max_steps;
        WP_PHASE = WP_VISIT;
    }
    WP_T_HI[lane] = select(bitcast<f32>(0xff800000u), box_interval(q_limit()).y, mine);
    workgroupBarrier();
    if mine {
        atomicOr(&WP_ACTIVE, 1u << lane);
    }
    workgroupBarrier();
    if lane == 0u {
        let in_packet = atomicLoad(&WP_ACTIVE);
        if P.wide_root_count != 0u {
            WP_CUR = WpEntry(leaf_offset(P.root), P.wide_root_count, in_packet, 0.0);
        } else {
            WP_CUR = WpEntry(P.root, 0u, in_packet, 0.0);
        }
        WP_PHASE = wp_visit_phase(in_packet);
        WP_GO = select(0u, 1u, in_packet != 0u);
    }
    loop {
        if workgroupUniformLoad(&WP_GO) == 0u {
            break;
        }
        wp_lane(lane);
        workgroupBarrier();
        if lane == 0u {
            wp_lead();
        }
    }
    if have {
        hits[slot] = Q_HIT;
    }
    guard_loops();
}
