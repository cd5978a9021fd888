//! Node keys and bit trails (Binder & Keller 2016, Fig. 2).
//!
//! The root has key 1; the children of key `k` are `2k` and `2k + 1`, its sibling is `k ^ 1` and
//! its parent `k >> 1`. The position of the leading one is the node's depth. A bit trail is
//! relative to the current node: bit `i` is set when the sibling of the ancestor `i` levels up
//! (bit 0: of the node itself) still has to be visited. Backtracking shifts key and trail right by
//! the trail's trailing zeros and flips the lowest bit of both.
//!
//! Everything is generic over the key width ([`Key`]: `u32` or `u64`); a tree of depth `d` needs
//! `d + 1` key bits, so `u32` serves trees of depth up to 31 ([`KeyWidth::for_depth`]).

mod width;
pub use width::KeyWidth;

#[cfg(test)]
mod naive_model_tests;

use core::fmt::Debug;
use core::ops::{BitAnd, BitOr, BitXor};

/// An unsigned integer used as node key and bit trail.
pub trait Key:
    Copy
    + Eq
    + Ord
    + Debug
    + Default
    + Send
    + Sync
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + BitXor<Output = Self>
    + 'static
{
    /// Number of bits.
    const BITS: u32;
    /// Zero (the empty trail).
    const ZERO: Self;
    /// One (the root key; the lowest trail bit).
    const ONE: Self;
    /// The width this type stands for.
    const WIDTH: KeyWidth;
    /// `self << n`.
    fn shl(self, n: u32) -> Self;
    /// `self >> n`.
    fn shr(self, n: u32) -> Self;
    /// Number of trailing zero bits.
    fn trailing_zeros(self) -> u32;
    /// Number of leading zero bits.
    fn leading_zeros(self) -> u32;
    /// `self & -self`: the lowest set bit alone.
    fn lowest_bit(self) -> Self;
    /// The low 32 bits.
    fn low_u32(self) -> u32;
    /// Widened to 64 bits.
    fn to_u64(self) -> u64;
    /// Narrowed from 64 bits (the caller guarantees it fits).
    fn from_u64(v: u64) -> Self;
    /// Whether zero.
    #[inline(always)]
    fn is_zero(self) -> bool {
        self == Self::ZERO
    }
}

macro_rules! impl_key {
    ($t:ty, $w:expr) => {
        impl Key for $t {
            const BITS: u32 = <$t>::BITS;
            const ZERO: Self = 0;
            const ONE: Self = 1;
            const WIDTH: KeyWidth = $w;
            #[inline(always)]
            fn shl(self, n: u32) -> Self {
                self << n
            }
            #[inline(always)]
            fn shr(self, n: u32) -> Self {
                self >> n
            }
            #[inline(always)]
            fn trailing_zeros(self) -> u32 {
                <$t>::trailing_zeros(self)
            }
            #[inline(always)]
            fn leading_zeros(self) -> u32 {
                <$t>::leading_zeros(self)
            }
            #[inline(always)]
            fn lowest_bit(self) -> Self {
                self & self.wrapping_neg()
            }
            #[inline(always)]
            fn low_u32(self) -> u32 {
                self as u32
            }
            #[inline(always)]
            fn to_u64(self) -> u64 {
                self as u64
            }
            #[inline(always)]
            fn from_u64(v: u64) -> Self {
                v as $t
            }
        }
    };
}
impl_key!(u32, KeyWidth::W32);
impl_key!(u64, KeyWidth::W64);

/// Key of the root.
#[inline(always)]
pub fn root<K: Key>() -> K {
    K::ONE
}

/// Key of a child: `2k` (left) or `2k + 1` (right).
#[inline(always)]
pub fn child<K: Key>(k: K, right: bool) -> K {
    let c = k.shl(1);
    if right {
        c ^ K::ONE
    } else {
        c
    }
}

/// Key of the parent: `k >> 1`.
#[inline(always)]
pub fn parent<K: Key>(k: K) -> K {
    k.shr(1)
}

/// Key of the sibling: `k ^ 1`.
#[inline(always)]
pub fn sibling<K: Key>(k: K) -> K {
    k ^ K::ONE
}

/// Depth of a node from its key (root: 0).
#[inline(always)]
pub fn depth<K: Key>(k: K) -> u32 {
    K::BITS - 1 - k.leading_zeros()
}

/// Descends one level: shifts key and trail, marks the trail when the other child is postponed,
/// and selects the right child in the key when `right`.
#[inline(always)]
pub fn descend<K: Key>(key: K, trail: K, right: bool, postponed_other: bool) -> (K, K) {
    let t = trail.shl(1);
    (child(key, right), if postponed_other { t ^ K::ONE } else { t })
}

/// One constant-time backtracking step: the key and trail of the next postponed node and the
/// number of levels climbed, or `None` when the trail is empty (traversal is done).
///
/// The target is the sibling of the ancestor `levels` levels up; its trail bit is consumed.
#[inline(always)]
pub fn backtrack<K: Key>(key: K, trail: K) -> Option<(K, K, u32)> {
    if trail.is_zero() {
        return None;
    }
    let n = trail.trailing_zeros();
    Some((key.shr(n) ^ K::ONE, trail.shr(n) ^ K::ONE, n))
}
