// Node keys and bit trails in 64 bits (`key::Key` for `u64`, and the free functions of
// `raytrail_core::key`) for trees deeper than 31 levels. WGSL has no 64-bit integers, so a key is
// a pair of words, x the low and y the high one. keys32.wgsl has the same API over `u32`.

alias Key = vec2<u32>;

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
    return vec2<u32>(0u);
}

fn key_one() -> Key {
    return vec2<u32>(1u, 0u);
}

// A key of value `v`.
fn key_from_u32(v: u32) -> Key {
    return vec2<u32>(v, 0u);
}

fn key_root() -> Key {
    return vec2<u32>(1u, 0u);
}

// `k << n` and `k >> n` for n < 64, which every caller guarantees. A WGSL shift by 32 or more is
// not a shift by that much, so whole-word moves and n = 0 (a cross-word shift by 32 - n) are
// handled apart.
fn key_shl(k: Key, n: u32) -> Key {
    if n == 0u {
        return k;
    }
    if n >= 32u {
        return vec2<u32>(0u, k.x << (n - 32u));
    }
    return vec2<u32>(k.x << n, (k.y << n) | (k.x >> (32u - n)));
}

fn key_shr(k: Key, n: u32) -> Key {
    if n == 0u {
        return k;
    }
    if n >= 32u {
        return vec2<u32>(k.y >> (n - 32u), 0u);
    }
    return vec2<u32>((k.x >> n) | (k.y << (32u - n)), k.y >> n);
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
    return all(a == b);
}

fn key_is_zero(k: Key) -> bool {
    return (k.x | k.y) == 0u;
}

// 64 for zero, as `u64::trailing_zeros`.
fn key_trailing_zeros(k: Key) -> u32 {
    if k.x != 0u {
        return countTrailingZeros(k.x);
    }
    return 32u + countTrailingZeros(k.y);
}

// `k & -k`: the borrow of the negation reaches the high word only when the low word is zero.
fn key_lowest_bit(k: Key) -> Key {
    if k.x != 0u {
        return vec2<u32>(k.x & (0u - k.x), 0u);
    }
    return vec2<u32>(0u, k.y & (0u - k.y));
}

fn key_low_u32(k: Key) -> u32 {
    return k.x;
}

// `key::depth` (root 0); the key must be nonzero.
fn key_depth(k: Key) -> u32 {
    if k.y != 0u {
        return 63u - countLeadingZeros(k.y);
    }
    return 31u - countLeadingZeros(k.x);
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

// `(k as u64 + d as u64) % h` of `hash::lookup`, as `(k mod h + d mod h) mod h`. `k mod h` is a
// long division of the low word's bits into the high word's remainder: the running remainder r
// stays below h, so `2r + bit` is below 2h and one subtraction reduces it; where h > 2^31 the
// doubling carries out of 32 bits and the subtraction wraps back to the right value.
fn key_add_mod(k: Key, d: u32, h: u32) -> u32 {
    var r = k.y % h;
    for (var i = 0u; i < 32u; i = i + 1u) {
        let carry = r >> 31u;
        let s = (r << 1u) | ((k.x >> (31u - i)) & 1u);
        r = select(s, s - h, carry != 0u || s >= h);
    }
    return add_mod(r, d % h, h);
}
