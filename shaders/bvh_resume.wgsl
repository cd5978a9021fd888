// Method (f), `hash-resume`: method (d), paused after every leaf that accepts a hit and resumed
// from the saved key and trail alone (`traverse::trace_pausing`, `Paused::of(..).resume(..)`;
// Binder & Keller 2016, Sec. 2.4). The register is not saved: the backtracking step is made
// before pausing, and the address comes back from the hash over every node.

fn trace(r: Ray) -> Hit {
    if !begin(r) {
        return miss();
    }
    register_init(P.root, key_root(), key_zero());
    // `for _ in 0..=max_steps`: max_steps + 1 steps, counted down so that a budget of u32::MAX
    // cannot wrap.
    var budget = P.max_steps;
    loop {
        let s = register_step();
        if s == STEP_DONE {
            break;
        }
        if s == STEP_AFTER_HIT {
            register_init(hash_lookup(R_KEY).x, R_KEY, R_TRAIL);
        }
        if budget == 0u {
            break;
        }
        budget = budget - 1u;
    }
    return Q_HIT;
}
