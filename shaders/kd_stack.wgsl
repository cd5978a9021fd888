// Method kd-stack: the standard kd-tree stack traversal (Horn et al. 2007, A.1; Wald 2004):
// descend to the child met first, push the other with its part of the segment, pop at a leaf
// (`kd::traverse::KdStackState`).

// A kd-tree of depth 64 never needs more entries.
const KD_STACK_CAPACITY: u32 = 64u;

var<private> KS_NODE: u32;
var<private> KS_T_MIN: f32;
var<private> KS_T_MAX: f32;
var<private> KS_LEN: u32;
var<private> KS_STACK: array<KdEntry, 64>;

fn kd_stack_step() -> u32 {
    let n = kd_node(KS_NODE);
    if !kd_is_leaf(n) {
        rec_node(KS_NODE);
        let c = kd_cross(n, KS_T_MIN, KS_T_MAX);
        if c.kind == CROSS_BOTH {
            if KS_LEN < KD_STACK_CAPACITY {
                KS_STACK[KS_LEN] = KdEntry(c.second, c.t_split, KS_T_MAX);
                KS_LEN = KS_LEN + 1u;
            }
            KS_NODE = c.first;
            KS_T_MAX = c.t_split;
        } else {
            KS_NODE = select(c.second, c.first, c.kind == CROSS_FIRST);
        }
        return STEP_CONTINUE;
    }
    if kd_leaf(KS_NODE, n, KS_T_MAX) || KS_LEN == 0u {
        return STEP_DONE;
    }
    KS_LEN = KS_LEN - 1u;
    let e = KS_STACK[KS_LEN];
    KS_NODE = e.node;
    KS_T_MIN = e.t_min;
    KS_T_MAX = e.t_max;
    rec_backtrack(0u, VIA_STACK_POP);
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
    KS_NODE = 0u;
    KS_T_MIN = s.t_enter;
    KS_T_MAX = s.t_exit;
    KS_LEN = 0u;
    var budget = P.max_steps;
    loop {
        if kd_stack_step() == STEP_DONE || budget == 0u {
            break;
        }
        budget = budget - 1u;
    }
    return Q_HIT;
}
