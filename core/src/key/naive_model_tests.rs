//! Key and bit-trail arithmetic against a naive model that walks explicit paths.
//!
//! The model keeps the path from the root as a list of (went right, other child postponed) pairs
//! and backtracks by popping levels until one has a postponed sibling. Random walks over random
//! trees must agree with the constant-time arithmetic at every step, for both widths.

use super::*;
extern crate alloc;
use alloc::vec::Vec;

/// A tiny deterministic generator (xorshift64*), so the test needs no dependency.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }
}

fn key_of<K: Key>(path: &[(bool, bool)]) -> K {
    path.iter().fold(K::ONE, |k, &(right, _)| child(k, right))
}

fn trail_of<K: Key>(path: &[(bool, bool)]) -> K {
    path.iter().fold(K::ZERO, |t, &(_, postponed)| if postponed { t.shl(1) ^ K::ONE } else { t.shl(1) })
}

fn walk<K: Key>(seed: u64, max_depth: usize) {
    let mut rng = Rng(seed | 1);
    let mut path: Vec<(bool, bool)> = Vec::new();
    let (mut key, mut trail) = (root::<K>(), K::ZERO);
    for _ in 0..2000 {
        let descend_more = path.len() < max_depth && rng.chance(60);
        if descend_more {
            let right = rng.chance(50);
            let postponed = rng.chance(40);
            (key, trail) = descend(key, trail, right, postponed);
            path.push((right, postponed));
        } else {
            // Naive backtracking: pop levels until one has a postponed sibling, then switch to it.
            let mut climbed = 0;
            while let Some(&(_, postponed)) = path.last() {
                if postponed {
                    break;
                }
                path.pop();
                climbed += 1;
            }
            let got = backtrack(key, trail);
            match path.last_mut() {
                None => {
                    assert_eq!(got, None, "empty trail must end traversal");
                    (key, trail) = (root(), K::ZERO);
                    continue;
                }
                Some(last) => {
                    last.0 = !last.0;
                    last.1 = false;
                    let (k, t, n) = got.expect("trail with a postponed level");
                    assert_eq!(n, climbed);
                    (key, trail) = (k, t);
                }
            }
        }
        assert_eq!(key, key_of::<K>(&path), "key after {path:?}");
        assert_eq!(trail, trail_of::<K>(&path), "trail after {path:?}");
        assert_eq!(depth(key) as usize, path.len());
        if let Some(&(right, _)) = path.last() {
            let mut other = path[..path.len() - 1].to_vec();
            other.push((!right, false));
            assert_eq!(sibling(key), key_of::<K>(&other));
            assert_eq!(parent(key), key_of::<K>(&path[..path.len() - 1]));
        }
    }
}

#[test]
fn u32_keys_match_naive_paths() {
    for seed in 0..200 {
        walk::<u32>(seed * 7919 + 1, 31);
    }
}

#[test]
fn u64_keys_match_naive_paths() {
    for seed in 0..200 {
        walk::<u64>(seed * 104_729 + 3, 63);
    }
}

#[test]
fn width_choice() {
    assert_eq!(KeyWidth::for_depth(31), Some(KeyWidth::W32));
    assert_eq!(KeyWidth::for_depth(32), Some(KeyWidth::W64));
    assert_eq!(KeyWidth::for_depth(64), None);
    let k: u32 = (0..31).fold(1u32, |k, _| child(k, true));
    assert_eq!(depth(k), 31);
}
