// The perfect hash from node keys to node addresses (`hash::lookup`; Binder & Keller 2016,
// Sec. 2.2.1-2.2.2): `h(k) = (k + d[k mod D]) mod H`. A negative displacement entry holds the
// address itself (internal addresses shifted by 0x80000000, leaf references as they are) and
// saves the second load. The key-width arithmetic is `key_add_mod` of the keys file.

// The node reference and whether the displacement entry held it (1) or the table did (0).
fn hash_lookup(key: Key) -> vec2<u32> {
    let d = hash_tables[key_low_u32(key) & P.d_mask];
    // The sign bit of the i32 entry.
    if d >= 0x80000000u {
        return vec2<u32>(select(d, d - 0x80000000u, d < 0xc0000000u), 1u);
    }
    let slot = key_add_mod(key, d, P.h);
    return vec2<u32>(hash_tables[P.d_mask + 1u + slot], 0u);
}
