// Methods (c) `uncle`, (d) `hash` and (e) `hash-disjoint` (DISJOINT), and the state method (f)
// pauses: stackless traversal with a node key, a bit trail and the most-recently-postponed-node
// register (Binder & Keller 2016, Algorithm 1; `traverse::RegisterState`). The fallback file
// composed before this one defines `fallback_find` for an empty register.

var<private> R_ADDR: u32;
var<private> R_KEY: Key;
var<private> R_TRAIL: Key;
// The most recently postponed node, or NONE.
var<private> R_MRPN: u32;
// Bit per level: the child intervals there overlap (kept by the mask). Only with DISJOINT.
var<private> R_OVERLAP: Key;
// Where the register's content came from, as a VIA_REGISTER code; written only when recording.
var<private> R_SOURCE: u32;

// `RegisterState::resume_at`: starts at `addr` with the given key and trail, register empty.
fn register_init(addr: u32, key: Key, trail: Key) {
    R_ADDR = addr;
    R_KEY = key;
    R_TRAIL = trail;
    R_MRPN = NONE;
    R_OVERLAP = key_zero();
    R_SOURCE = VIA_REGISTER;
}

// Loads the register from the current node's links when the trail names one of them as the next
// target: the lowest set trail bit among 1..=3 (bit 0 is never set with an empty register).
// Absent links (NONE) leave the register empty: their level is above the root.
fn register_refill(links: vec3<u32>) {
    let bits = key_low_u32(key_shr(R_TRAIL, 1u)) & 7u;
    if bits != 0u {
        let j = countTrailingZeros(bits);
        R_MRPN = links[j];
        if RECORD != 0u {
            R_SOURCE = VIA_REGISTER + 1u + j;
        }
    }
}

// One constant-time backtracking step: the register serves it if set, else the fallback.
fn register_backtrack(links: vec3<u32>, more: u32) -> u32 {
    let b = key_backtrack(R_KEY, R_TRAIL);
    if !b.ok {
        return STEP_DONE;
    }
    R_KEY = b.key;
    R_TRAIL = b.trail;
    if DISJOINT {
        R_OVERLAP = key_shr(R_OVERLAP, b.levels);
    }
    if !is_none(R_MRPN) {
        R_ADDR = R_MRPN;
        R_MRPN = NONE;
        rec_backtrack(b.levels, R_SOURCE);
    } else {
        R_ADDR = fallback_find(b.key, b.levels, links);
    }
    return more;
}

// `RegisterState::step`: processes one node.
fn register_step() -> u32 {
    // Only damaged tables lead to an absent node; end rather than read out of bounds.
    if is_none(R_ADDR) {
        return STEP_DONE;
    }
    rec_node(R_ADDR);
    if !is_leaf(R_ADDR) {
        let node = load_node(R_ADDR);
        let links = vec3<u32>(node.links, NONE);
        if is_none(R_MRPN) {
            register_refill(links);
        }
        let d = order_children(node, q_limit());
        if d.kind == DESCENT_NEITHER {
            return register_backtrack(links, STEP_CONTINUE);
        }
        let postpone = d.kind == DESCENT_BOTH;
        if postpone {
            R_MRPN = node.children[1u - d.first];
            if RECORD != 0u {
                R_SOURCE = VIA_REGISTER;
            }
        }
        R_ADDR = node.children[d.first];
        let kt = key_descend(R_KEY, R_TRAIL, d.first == 1u, postpone);
        R_KEY = kt.key;
        R_TRAIL = kt.trail;
        if DISJOINT {
            R_OVERLAP = key_or(key_shl(R_OVERLAP, 1u), select(key_zero(), key_one(), postpone && !d.disjoint));
        }
        return STEP_CONTINUE;
    }
    let leaf = intersect_leaf(leaf_offset(R_ADDR));
    if q_is_answered() {
        return STEP_DONE;
    }
    // Sec. 2.3: a hit masks the trail with the overlapping levels, and empties the register if
    // its level was masked out.
    if DISJOINT && leaf.hit {
        if key_is_zero(key_and(key_lowest_bit(R_TRAIL), R_OVERLAP)) {
            R_MRPN = NONE;
        }
        R_TRAIL = key_and(R_TRAIL, R_OVERLAP);
    }
    if is_none(R_MRPN) {
        register_refill(leaf.links);
    }
    return register_backtrack(leaf.links, select(STEP_CONTINUE, STEP_AFTER_HIT, leaf.hit));
}
