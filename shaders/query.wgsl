// The answer being built for one ray (`traverse::QueryState`) and the per-ray prelude
// (`traverse::begin`).

var<private> Q_HIT: Hit;

// `QueryState::limit`: the closest hit so far, or the ray's tmax (inclusive).
fn q_limit() -> f32 {
    return select(C.tmax, Q_HIT.t, Q_HIT.prim != NO_PRIM);
}

// `QueryState::offer`: takes a hit that beats the current one (smaller t, ties to the smaller
// primitive id).
fn q_offer(h: TriHit, prim: u32) -> bool {
    let cur = Q_HIT;
    if cur.prim == NO_PRIM || h.t < cur.t || (h.t == cur.t && prim < cur.prim) {
        Q_HIT = Hit(h.t, prim, h.u, h.v);
        return true;
    }
    return false;
}

// `QueryState::is_answered`: an any-hit query that found a hit.
fn q_is_answered() -> bool {
    return ANY_HIT && Q_HIT.prim != NO_PRIM;
}

// `traverse::begin`: false for a ray every method treats as a miss (not traceable, or with
// distances that overflow); otherwise sets up the per-ray constants and an empty answer.
fn begin(r: Ray) -> bool {
    Q_HIT = miss();
    if !is_traceable(r) {
        return false;
    }
    tri_prepare(r);
    return ctx_init(r);
}
