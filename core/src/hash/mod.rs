//! Perfect hashing of node keys to node addresses (Binder & Keller 2016, Sec. 2.2.1-2.2.2).
//!
//! `h(k) = (k + d[k mod D]) mod H`, with `D` a power of two (so `k mod D` is `k & (D - 1)` on the
//! low 32 bits of the key) and `H` odd, hence co-prime with `D`. A displacement entry whose bucket
//! holds a single key stores that key's node address directly, marked by the sign bit, and saves
//! the second load.

#[cfg(feature = "alloc")]
mod build;
#[cfg(feature = "alloc")]
mod select;
#[cfg(feature = "alloc")]
pub use build::{HashStats, PerfectHash};
#[cfg(feature = "alloc")]
pub use select::{keys_to_hash, HashCoverage};

use crate::bvh2::{BvhMemory, NodeRef};
use crate::key::Key;
use bytemuck::{Pod, Zeroable};

/// The two table sizes a lookup needs.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct HashShape {
    /// `D - 1`, with `D` the displacement table size (a power of two).
    pub d_mask: u32,
    /// `H`, the hash table size (odd).
    pub h: u32,
}

/// Encodes a node address as a direct displacement entry: internal addresses shifted by
/// `0x8000_0000`, leaf references (already at or above `0xC000_0000`) as they are.
#[inline]
pub fn encode_direct(r: NodeRef) -> i32 {
    if r.is_leaf() {
        r.0 as i32
    } else {
        (r.0 | 0x8000_0000) as i32
    }
}

/// Maps a key to its node's address in constant time; `direct` tells whether the displacement
/// entry held the address itself (one load instead of two).
#[inline(always)]
pub fn lookup<K: Key, M: BvhMemory + ?Sized>(mem: &M, shape: HashShape, key: K) -> (NodeRef, bool) {
    lookup_in(|i| mem.displacement(i), |i| mem.hash_cell(i), shape, key)
}

/// [`lookup`] in tables read through `displacement` and `cell` (entry and cell by index), for
/// memories other than a BVH2's (the wide trees' keyed memory).
#[inline(always)]
pub fn lookup_in<K: Key>(
    displacement: impl Fn(u32) -> i32,
    cell: impl Fn(u32) -> u32,
    shape: HashShape,
    key: K,
) -> (NodeRef, bool) {
    let d = displacement(key.low_u32() & shape.d_mask);
    if d < 0 {
        let a = d as u32;
        let r = if a < 0xC000_0000 { a - 0x8000_0000 } else { a };
        (NodeRef(r), true)
    } else {
        // Reduced first: a depth-63 key plus a displacement can exceed 2^64 (the builder places
        // keys the same way, and the GPU's 64-bit emulation computes this very expression).
        let h = shape.h as u64;
        let slot = (key.to_u64() % h + d as u64) % h;
        (NodeRef(cell(slot as u32)), false)
    }
}
