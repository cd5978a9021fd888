// Method bvh4-hash: the 4-wide tree in the stack traversal's order without a stack
// (`wide::trail::run`). A ray keeps its current child, its node key (two bits per level: child
// slot s of key k is (k << 2) | s) and a bit trail (bit i: the ancestor i levels up may have
// siblings left to visit). A backtrack finds the parent of the ancestor whose siblings are due
// through the perfect hash over the node keys (hash.wgsl), tests that parent's children again over
// [tmin - slack, +inf] and takes the next one in the visiting order entered within the slack of
// the closest hit (`wide::trail::backtrack`, `successor`); a register holding the parent of the
// trail's lowest level, where known, spares most lookups. Keys and trails are the keys file's
// (32 bits, or a pair of words for trees deeper than 15 levels); WK_BITS, the key bits per level,
// comes in the generated header.

// Key of child `slot` of the node keyed `key` (`wide::keyed::child_key`).
fn wk_child(key: Key, slot: u32) -> Key {
    return key_or(key_shl(key, WK_BITS), key_from_u32(slot));
}

// A backtrack's result: `ok` false when the trail ran out (the ray is done).
struct WideBacktrack {
    ok: bool,
    c: WideChild,
    key: Key,
    trail: Key,
}

// The register: the parent of the level of the trail's lowest set bit, when WK_REG_OK.
var<private> WK_REG: u32;
var<private> WK_REG_OK: bool;

// `wide::trail::successor` over WT_T (entry distances, +inf for a miss) and the hit `mask` from
// `wide_test`: the least child after `slot` entered within `reach`, by (distance, slot) or by slot
// for any-hit queries, and how many qualify. Every index into WT_T is a constant once unrolled.
struct WideNext {
    slot: u32,
    count: u32,
}

fn wk_successor(mask: u32, slot: u32, reach: f32) -> WideNext {
    var cur = 0.0;
    for (var i = 0u; i < WIDE_W; i = i + 1u) {
        if i == slot {
            cur = WT_T[i];
        }
    }
    var best = WIDE_W;
    var best_t = 0.0;
    var count = 0u;
    for (var i = 0u; i < WIDE_W; i = i + 1u) {
        let t = WT_T[i];
        var after = i > slot;
        if !ANY_HIT {
            after = t > cur || (t == cur && i > slot);
        }
        if (mask & (1u << i)) != 0u && t <= reach && after {
            count = count + 1u;
            // Slots come in increasing order, so a tie keeps the smaller one.
            if best == WIDE_W || (!ANY_HIT && t < best_t) {
                best = i;
                best_t = t;
            }
        }
    }
    return WideNext(best, count);
}

// `wide::trail::backtrack`.
fn wk_backtrack(key_in: Key, trail_in: Key) -> WideBacktrack {
    var key = key_in;
    var trail = trail_in;
    loop {
        if key_is_zero(trail) {
            break;
        }
        let n = key_trailing_zeros(trail);
        let ancestor = key_shr(key, WK_BITS * n);
        let slot = key_low_u32(ancestor) & (WIDE_W - 1u);
        let parent_key = key_shr(ancestor, WK_BITS);
        var parent = WK_REG;
        if WK_REG_OK {
            rec_backtrack(n, VIA_REGISTER);
        } else {
            let found = hash_lookup(parent_key);
            rec_backtrack(n, VIA_HASH + found.y);
            parent = found.x;
        }
        WK_REG_OK = false;
        let iv = box_interval(q_limit());
        let mask = wide_test(parent, iv.x, bitcast<f32>(0x7f800000u));
        key = ancestor;
        trail = key_xor(key_shr(trail, n), key_one());
        let next = wk_successor(mask, slot, q_limit() + C.t_slack);
        if next.slot < WIDE_W {
            let s = wide_slot(parent, next.slot);
            if !s.ok {
                break;
            }
            if next.count > 1u {
                trail = key_or(trail, key_one());
                WK_REG = parent;
                WK_REG_OK = true;
            }
            return WideBacktrack(true, s.c, wk_child(parent_key, next.slot), trail);
        }
    }
    return WideBacktrack(false, WideChild(0u, 0u), key, trail);
}

// `wide::trail::run`: the step always runs once, then the budget is checked.
fn trace(r: Ray) -> Hit {
    if !begin(r) {
        return miss();
    }
    var cur = wide_root();
    var key = key_root();
    var trail = key_zero();
    WK_REG_OK = false;
    var budget = P.max_steps;
    loop {
        rec_node(wide_ref(cur));
        var descended = false;
        if cur.count != 0u {
            wide_leaf(cur.child, cur.count);
            if q_is_answered() {
                break;
            }
        } else {
            let iv = box_interval(q_limit());
            let cur_node = cur.child;
            let mask = wide_test(cur_node, iv.x, iv.y);
            if mask != 0u {
                let first_slot = wide_order(mask);
                let first = wide_slot(cur_node, first_slot);
                if !first.ok {
                    break;
                }
                cur = first.c;
                key = wk_child(key, first_slot);
                trail = key_shl(trail, 1u);
                if countOneBits(mask) > 1u {
                    trail = key_or(trail, key_one());
                    WK_REG = cur_node;
                    WK_REG_OK = true;
                }
                descended = true;
            }
        }
        if !descended {
            let b = wk_backtrack(key, trail);
            if !b.ok {
                break;
            }
            cur = b.c;
            key = b.key;
            trail = b.trail;
        }
        if budget == 0u {
            break;
        }
        budget = budget - 1u;
    }
    return Q_HIT;
}
