// Every hit along a ray (`raytrail_core::all_hits`), in place of query.wgsl and entry.wgsl: the
// wide stack walk (wide_stack.wgsl) with a hit list for an answer. The list lives in the ray's
// `records` slot, kept in order of (t, prim) as hits come; its last distance culls the walk once
// it holds `all_hits_keep` hits (the caller's limit and one more, whose presence says the list
// was cut), as `HitList` culls on the CPU. A triangle met twice (in two leaves of a tree with
// split references: the same hit bit for bit) is kept once; with `all_hits_merge`, of hits at one
// t (numerically: -0 equals 0) only the one of the lower primitive id. The list is then the
// CPU's: the nearest hits of the same set under the same total order, whatever the visiting
// order.
//
// A ray's slot (`P.record_stride` words): [0] hits held (its top bit set where the walk ran out of
// steps, which only a broken tree makes it do: the list then says it is cut, as the CPU's does),
// then up to `P.record_cap` hits of four words (t, prim, u, v). A list that fills a slot smaller than the keep may have lost hits; the
// host traces such rays again with a larger slot (backends/wgpu/src/all_hits.rs).

// The closest-hit answer wide_stack.wgsl's `trace` returns; this kernel's entry does not call it.
var<private> Q_HIT: Hit;
// Where the ray's slot starts in `records`.
var<private> AH_BASE: u32;
// Hits the list keeps at most: the keep, within the slot.
var<private> AH_KEEP: u32;

fn ah_t(k: u32) -> f32 {
    return bitcast<f32>(records[AH_BASE + 1u + 4u * k]);
}

fn ah_prim(k: u32) -> u32 {
    return records[AH_BASE + 2u + 4u * k];
}

fn ah_copy(src: u32, dst: u32) {
    for (var w = 1u; w <= 4u; w = w + 1u) {
        records[AH_BASE + w + 4u * dst] = records[AH_BASE + w + 4u * src];
    }
}

fn ah_write(k: u32, h: TriHit, prim: u32) {
    let at = AH_BASE + 1u + 4u * k;
    records[at] = bitcast<u32>(h.t);
    records[at + 1u] = prim;
    records[at + 2u] = bitcast<u32>(h.u);
    records[at + 3u] = bitcast<u32>(h.v);
}

// `HitList::limit`: the ray's tmax until the list is full, then its last distance (inclusive: an
// equal t with a lower primitive id still displaces the last hit).
fn q_limit() -> f32 {
    let n = records[AH_BASE];
    if n >= AH_KEEP {
        return ah_t(n - 1u);
    }
    return C.tmax;
}

// `HitList::offer`: the hit goes in at its place in the order, unless the list holds it already
// (or, merging, a hit at its t of a lower id); a full list drops its last. Never "taken": no
// query ends on a hit.
fn q_offer(h: TriHit, prim: u32) -> bool {
    let n = records[AH_BASE];
    // Where it goes: after every hit that orders before it or equals it.
    var at = n;
    loop {
        if at == 0u {
            break;
        }
        let t = ah_t(at - 1u);
        if t < h.t || (t == h.t && ah_prim(at - 1u) <= prim) {
            break;
        }
        at = at - 1u;
    }
    if at > 0u && ah_t(at - 1u) == h.t && (P.all_hits_merge != 0u || ah_prim(at - 1u) == prim) {
        return false;
    }
    if P.all_hits_merge != 0u && at < n && ah_t(at) == h.t {
        // The hit of its t already held has a higher id: this one takes its place.
        ah_write(at, h, prim);
        return false;
    }
    if at >= AH_KEEP {
        return false;
    }
    let held = min(n + 1u, AH_KEEP);
    for (var k = held - 1u; k > at; k = k - 1u) {
        ah_copy(k - 1u, k);
    }
    ah_write(at, h, prim);
    records[AH_BASE] = held;
    return false;
}

fn q_is_answered() -> bool {
    return false;
}

// `traverse::begin` for a closest-hit walk, with an empty list.
fn begin(r: Ray) -> bool {
    Q_HIT = miss();
    records[AH_BASE] = 0u;
    if !is_traceable(r) {
        return false;
    }
    tri_prepare(r);
    return ctx_init(r);
}

fn item_count() -> u32 {
    return P.ray_count;
}

// `WideState::run` from the root, as wide_stack.wgsl's `wide_run`; false where the step budget
// ran out with the walk unfinished.
fn ah_run() -> bool {
    WS_CURRENT = wide_root();
    WS_HAS_CURRENT = true;
    WS_LEN = 0u;
    var budget = P.max_steps;
    loop {
        if wide_step() == STEP_DONE {
            return true;
        }
        if budget == 0u {
            return false;
        }
        budget = budget - 1u;
    }
    return true;
}

fn run_item(i: u32) {
    AH_BASE = i * P.record_stride;
    AH_KEEP = min(P.all_hits_keep, P.record_cap);
    if begin(rays[i]) && !ah_run() {
        records[AH_BASE] = records[AH_BASE] | 0x80000000u;
    }
    hits[i] = miss();
}
