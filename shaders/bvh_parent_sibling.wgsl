// Method (b), `parent-sibling`: stackless traversal with parent and sibling links and a bit trail
// (Áfra, Szirmay-Kalos & Keller 2014; `traverse::ParentSiblingState`). Backtracking climbs parent
// links until the trail shows a postponed sibling, then follows that sibling link; an empty trail
// ends traversal without returning to the root. Links are `[parent, sibling]`.

var<private> PS_ADDR: u32;
var<private> PS_TRAIL: Key;

// Climbs from the current node, whose `[parent, sibling]` links are given.
fn parent_sibling_backtrack(first: vec2<u32>) -> u32 {
    if key_is_zero(PS_TRAIL) {
        return STEP_DONE;
    }
    var links = first;
    var levels = 0u;
    while key_is_zero(key_and(PS_TRAIL, key_one())) {
        let parent = links.x;
        if is_none(parent) || is_leaf(parent) {
            return STEP_DONE;
        }
        rec_link_read();
        links = bvh[parent * 4u + 3u].zw;
        PS_TRAIL = key_shr(PS_TRAIL, 1u);
        levels = levels + 1u;
    }
    PS_TRAIL = key_xor(PS_TRAIL, key_one());
    PS_ADDR = links.y;
    rec_backtrack(levels, VIA_ITERATIVE);
    return STEP_CONTINUE;
}

// `ParentSiblingState::step`: processes one node.
fn parent_sibling_step() -> u32 {
    // Only damaged tables lead to an absent node; end rather than read out of bounds.
    if is_none(PS_ADDR) {
        return STEP_DONE;
    }
    rec_node(PS_ADDR);
    var links: vec2<u32>;
    if !is_leaf(PS_ADDR) {
        let node = load_node(PS_ADDR);
        let d = order_children(node, q_limit());
        if d.kind != DESCENT_NEITHER {
            // The trail marks the level when the other child is postponed.
            PS_TRAIL = key_xor(key_shl(PS_TRAIL, 1u), select(key_zero(), key_one(), d.kind == DESCENT_BOTH));
            PS_ADDR = node.children[d.first];
            return STEP_CONTINUE;
        }
        links = node.links;
    } else {
        let leaf = intersect_leaf(leaf_offset(PS_ADDR));
        if q_is_answered() {
            return STEP_DONE;
        }
        links = leaf.links.xy;
    }
    return parent_sibling_backtrack(links);
}

fn trace(r: Ray) -> Hit {
    if !begin(r) {
        return miss();
    }
    PS_ADDR = P.root;
    PS_TRAIL = key_zero();
    var budget = P.max_steps;
    loop {
        if parent_sibling_step() == STEP_DONE || budget == 0u {
            break;
        }
        budget = budget - 1u;
    }
    return Q_HIT;
}
