// Method (a), `stack`, and its pruning twin `stack-disjoint` (DISJOINT): the while-while order of
// Aila & Laine 2009 with a stack (`traverse::StackState`).

const STACK_CAPACITY: u32 = 64u;

var<private> S_ADDR: u32;
var<private> S_LEN: u32;
var<private> S_STACK: array<u32, 64>;
// Bits 0..31 and 32..63: the entry's interval was disjoint from its sibling's.
var<private> S_DISJOINT: vec2<u32>;

fn stack_set_disjoint(i: u32, on: bool) {
    let word = i / 32u;
    let bit = 1u << (i % 32u);
    let v = select(S_DISJOINT[word] & ~bit, S_DISJOINT[word] | bit, on);
    S_DISJOINT[word] = v;
}

fn stack_is_disjoint(i: u32) -> bool {
    return (S_DISJOINT[i / 32u] & (1u << (i % 32u))) != 0u;
}

fn stack_pop(after_hit: bool) -> u32 {
    if S_LEN == 0u {
        return STEP_DONE;
    }
    S_LEN = S_LEN - 1u;
    S_ADDR = S_STACK[S_LEN];
    rec_backtrack(0u, VIA_STACK_POP);
    return select(STEP_CONTINUE, STEP_AFTER_HIT, after_hit);
}

fn stack_drop_disjoint() {
    var kept = 0u;
    for (var i = 0u; i < S_LEN; i = i + 1u) {
        if !stack_is_disjoint(i) {
            S_STACK[kept] = S_STACK[i];
            kept = kept + 1u;
        }
    }
    S_LEN = kept;
    S_DISJOINT = vec2<u32>(0u);
}

fn stack_step() -> u32 {
    if is_none(S_ADDR) {
        return STEP_DONE;
    }
    rec_node(S_ADDR);
    if !is_leaf(S_ADDR) {
        let node = load_node(S_ADDR);
        let d = order_children(node, q_limit());
        if d.kind == DESCENT_ONE {
            S_ADDR = node.children[d.first];
            return STEP_CONTINUE;
        }
        if d.kind == DESCENT_BOTH {
            if S_LEN < STACK_CAPACITY {
                S_STACK[S_LEN] = node.children[1u - d.first];
                if DISJOINT {
                    stack_set_disjoint(S_LEN, d.disjoint);
                }
                S_LEN = S_LEN + 1u;
            }
            S_ADDR = node.children[d.first];
            return STEP_CONTINUE;
        }
        return stack_pop(false);
    }
    let leaf = intersect_leaf(leaf_offset(S_ADDR));
    if q_is_answered() {
        return STEP_DONE;
    }
    if DISJOINT && leaf.hit {
        stack_drop_disjoint();
    }
    return stack_pop(leaf.hit);
}

fn trace(r: Ray) -> Hit {
    if !begin(r) {
        return miss();
    }
    S_ADDR = P.root;
    S_LEN = 0u;
    S_DISJOINT = vec2<u32>(0u);
    var budget = P.max_steps;
    loop {
        if stack_step() == STEP_DONE || budget == 0u {
            break;
        }
        budget = budget - 1u;
    }
    return Q_HIT;
}
