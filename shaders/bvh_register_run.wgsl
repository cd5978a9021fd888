// Methods (c) `uncle`, (d) `hash` and (e) `hash-disjoint`: a `RegisterState` from the root,
// stepped until done or out of budget (`traverse::trace_ray`'s `drive!`).

fn trace(r: Ray) -> Hit {
    if !begin(r) {
        return miss();
    }
    register_init(P.root, key_root(), key_zero());
    var budget = P.max_steps;
    loop {
        if register_step() == STEP_DONE || budget == 0u {
            break;
        }
        budget = budget - 1u;
    }
    return Q_HIT;
}
