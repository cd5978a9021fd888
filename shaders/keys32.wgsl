// Node keys and bit trails in 32 bits (`key::Key` for `u32`, and the free functions of
// `raytrail_core::key`): root 1, children 2k and 2k + 1, the trail relative to the current node.
// keys64.wgsl has the same API over a pair of words; the method files use only this API.

alias Key = u32;

// Key and trail after one step down (`key::descend`).
struct KeyTrail {
    key: Key,
    trail: Key,
}

// One backtracking step (`key::backtrack`): `ok` false when the trail is empty (`None`).
struct KeyBacktrack {
    ok: bool,
    key: Key,
    trail: Key,
    levels: u32,
}

fn key_zero() -> Key {
    return 0u;
}

fn key_one() -> Key {
    return 1u;
}

// A key of value `v`.
fn key_from_u32(v: u32) -> Key {
    return v;
}

fn key_root() -> Key {
    return 1u;
}

// `k << n` and `k >> n` for n < 32, which every caller guarantees (shifts by 1, or by the trailing
// zeros of a nonzero trail).
fn key_shl(k: Key, n: u32) -> Key {
    return k << n;
}

fn key_shr(k: Key, n: u32) -> Key {
    return k >> n;
}

fn key_and(a: Key, b: Key) -> Key {
    return a & b;
}

fn key_or(a: Key, b: Key) -> Key {
    return a | b;
}

fn key_xor(a: Key, b: Key) -> Key {
    return a ^ b;
}

fn key_eq(a: Key, b: Key) -> bool {
    return a == b;
}

fn key_is_zero(k: Key) -> bool {
    return k == 0u;
}

// 32 for zero, as `u32::trailing_zeros`.
fn key_trailing_zeros(k: Key) -> u32 {
    return countTrailingZeros(k);
}

// `k & -k`.
fn key_lowest_bit(k: Key) -> Key {
    return k & (0u - k);
}

fn key_low_u32(k: Key) -> u32 {
    return k;
}

// `key::depth` (root 0); the key must be nonzero.
fn key_depth(k: Key) -> u32 {
    return 31u - countLeadingZeros(k);
}

// `key::child`.
fn key_child(k: Key, right: bool) -> Key {
    return key_xor(key_shl(k, 1u), select(key_zero(), key_one(), right));
}

// `key::descend`: the trail marks the other child when it is postponed.
fn key_descend(key: Key, trail: Key, right: bool, postponed_other: bool) -> KeyTrail {
    let t = key_shl(trail, 1u);
    return KeyTrail(key_child(key, right), select(t, key_xor(t, key_one()), postponed_other));
}

// `key::backtrack`: key and trail shifted by the trail's trailing zeros, lowest bit flipped.
fn key_backtrack(key: Key, trail: Key) -> KeyBacktrack {
    if key_is_zero(trail) {
        return KeyBacktrack(false, key, trail, 0u);
    }
    let n = key_trailing_zeros(trail);
    return KeyBacktrack(true, key_xor(key_shr(key, n), key_one()), key_xor(key_shr(trail, n), key_one()), n);
}

// `(a + b) mod h` for a, b < h, without overflow when h > 2^31.
fn add_mod(a: u32, b: u32, h: u32) -> u32 {
    return select(a + b, a - (h - b), a >= h - b);
}

// `(k as u64 + d as u64) % h` of `hash::lookup`: the sum can exceed 32 bits, so both terms are
// reduced first.
fn key_add_mod(k: Key, d: u32, h: u32) -> u32 {
    return add_mod(k % h, d % h, h);
}
