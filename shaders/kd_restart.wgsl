// Methods kd-restart (KD_MODE 0), kd-push-down (1) and kd-short-stack (2) of Horn et al. 2007,
// A.2-A.4, one state for the three (`kd::traverse::KdRestartState`):
// - restart: after a leaf, step the segment's start to the leaf's exit and descend from the root;
// - push-down: while a descent has entered only one child at every node, the restart point moves
//   down with it;
// - short stack: push-down plus a stack of `P.short_stack` entries (at most SHORT_STACK_MAX); a
//   push onto a full stack drops the bottom entry, and popping an empty one restarts.

const KR_PUSH_DOWN: bool = KD_MODE != 0u;

var<private> KR_NODE: u32;
var<private> KR_T_MIN: f32;
var<private> KR_T_MAX: f32;
var<private> KR_SCENE_MAX: f32;
// Where a restart begins (the root, or lower with push-down).
var<private> KR_RESTART_AT: u32;
// The current descent has met only single-child nodes since it began.
var<private> KR_PUSHING: bool;
var<private> KR_CAPACITY: u32;
var<private> KR_LEN: u32;
var<private> KR_STACK: array<KdEntry, SHORT_STACK_MAX>;

fn kd_restart_push(e: KdEntry) {
    if KR_CAPACITY == 0u {
        return;
    }
    if KR_LEN == KR_CAPACITY {
        // Full: the bottom entry (farthest along the ray) is dropped; a restart will find it.
        for (var i = 1u; i < KR_LEN; i = i + 1u) {
            KR_STACK[i - 1u] = KR_STACK[i];
        }
        KR_LEN = KR_LEN - 1u;
    }
    KR_STACK[KR_LEN] = e;
    KR_LEN = KR_LEN + 1u;
}

fn kd_restart_step() -> u32 {
    let n = kd_node(KR_NODE);
    if !kd_is_leaf(n) {
        rec_node(KR_NODE);
        let c = kd_cross(n, KR_T_MIN, KR_T_MAX);
        if c.kind == CROSS_BOTH {
            kd_restart_push(KdEntry(c.second, c.t_split, KR_T_MAX));
            KR_NODE = c.first;
            KR_T_MAX = c.t_split;
            KR_PUSHING = false;
        } else {
            KR_NODE = select(c.second, c.first, c.kind == CROSS_FIRST);
            if KR_PUSHING {
                KR_RESTART_AT = KR_NODE;
            }
        }
        return STEP_CONTINUE;
    }
    if kd_leaf(KR_NODE, n, KR_T_MAX) {
        return STEP_DONE;
    }
    if KR_LEN > 0u {
        KR_LEN = KR_LEN - 1u;
        let e = KR_STACK[KR_LEN];
        KR_NODE = e.node;
        KR_T_MIN = e.t_min;
        KR_T_MAX = e.t_max;
        KR_PUSHING = false;
        rec_backtrack(0u, VIA_STACK_POP);
        return STEP_CONTINUE;
    }
    if KR_T_MAX >= KR_SCENE_MAX {
        return STEP_DONE;
    }
    KR_NODE = KR_RESTART_AT;
    KR_T_MIN = KR_T_MAX;
    KR_T_MAX = KR_SCENE_MAX;
    KR_PUSHING = KR_PUSH_DOWN;
    rec_backtrack(0u, VIA_RESTART);
    return STEP_CONTINUE;
}

// `trace_kd_ray`'s drive loop: the step always runs once, then the budget is checked.
fn trace(r: Ray) -> Hit {
    if !begin(r) {
        return miss();
    }
    let s = scene_interval();
    if !s.hit {
        return miss();
    }
    KR_NODE = 0u;
    KR_T_MIN = s.t_enter;
    KR_T_MAX = s.t_exit;
    KR_SCENE_MAX = s.t_exit;
    KR_RESTART_AT = 0u;
    KR_PUSHING = KR_PUSH_DOWN;
    KR_CAPACITY = select(0u, min(P.short_stack, SHORT_STACK_MAX), KD_MODE == 2u);
    KR_LEN = 0u;
    var budget = P.max_steps;
    loop {
        if kd_restart_step() == STEP_DONE || budget == 0u {
            break;
        }
        budget = budget - 1u;
    }
    return Q_HIT;
}
