// Method (d)'s fallback when the register is empty (`traverse::PerfectHashLookup`): the perfect
// hash maps the target's key to its address in constant time (Algorithm 1).

// The node whose key is `key`, `levels` levels up and across; `links` is unused here.
fn fallback_find(key: Key, levels: u32, links: vec3<u32>) -> u32 {
    let found = hash_lookup(key);
    rec_backtrack(levels, VIA_HASH + found.y);
    return found.x;
}
