//! Ordering a node's hit children by entry distance with a sorting network (Guthe 2014, Sec. 4.1):
//! a bitonic network of compare-and-swaps done by conditional assignment, whose stages hold
//! independent compare-and-swaps (two for four children, four for eight) where an insertion or
//! merge sort would chain them.

/// Sorts `W` (a power of two) lanes by `(key, slot)` ascending, carrying the slots along: 6
/// compare-and-swaps for 4 lanes (three stages of two), 24 for 8 (six stages of four). Keys are
/// entry distances (never NaN); equal keys go to the smaller slot, so the order is total and any
/// correct sort agrees with it.
#[inline(always)]
pub fn sort_network<const W: usize>(keys: &mut [f32; W], slots: &mut [u32; W]) {
    sort_network_without(keys, slots, usize::MAX);
}

/// [`sort_network`] with compare-and-swap number `dropped` (counting from 0 in network order)
/// left out, or none for `usize::MAX`: the fault the conformance suite must catch.
#[inline(always)]
pub fn sort_network_without<const W: usize>(keys: &mut [f32; W], slots: &mut [u32; W], dropped: usize) {
    let mut n = 0;
    let mut cas = |keys: &mut [f32; W], slots: &mut [u32; W], i: usize, j: usize| {
        if n != dropped {
            compare_and_swap(keys, slots, i, j);
        }
        n += 1;
    };
    let mut size = 2;
    while size <= W {
        // Merge two sorted runs of `size / 2`: compare each lane with its mirror in the block...
        for i in 0..W {
            let block = i / size * size;
            let mirror = block + size - 1 - (i - block);
            if i < mirror {
                cas(keys, slots, i, mirror);
            }
        }
        // ... then clean each half.
        let mut d = size / 4;
        while d >= 1 {
            for i in 0..W {
                if i & d == 0 && i + d < W {
                    cas(keys, slots, i, i + d);
                }
            }
            d /= 2;
        }
        size *= 2;
    }
}

/// Puts the smaller of lanes `i < j` (by key, then slot) in `i`, by conditional assignment.
#[inline(always)]
fn compare_and_swap<const W: usize>(keys: &mut [f32; W], slots: &mut [u32; W], i: usize, j: usize) {
    let (ki, kj, si, sj) = (keys[i], keys[j], slots[i], slots[j]);
    let swap = kj < ki || (kj == ki && sj < si);
    keys[i] = if swap { kj } else { ki };
    keys[j] = if swap { ki } else { kj };
    slots[i] = if swap { sj } else { si };
    slots[j] = if swap { si } else { sj };
}

/// The reference order: an insertion sort by `(key, slot)`.
#[inline(always)]
pub fn sort_insertion<const W: usize>(keys: &mut [f32; W], slots: &mut [u32; W]) {
    for i in 1..W {
        let mut j = i;
        while j > 0 && (keys[j] < keys[j - 1] || (keys[j] == keys[j - 1] && slots[j] < slots[j - 1])) {
            keys.swap(j, j - 1);
            slots.swap(j, j - 1);
            j -= 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every permutation of `0..W` with ties (keys `v / 2`), through the network and the
    /// insertion sort; returns how many permutations a network missing `dropped` got wrong.
    fn wrong<const W: usize>(dropped: usize) -> usize {
        let mut wrong = 0;
        let mut perm: [u32; W] = core::array::from_fn(|i| i as u32);
        // Heap's algorithm over every permutation.
        let mut c = [0usize; W];
        let mut check = |p: &[u32; W]| {
            let keys: [f32; W] = core::array::from_fn(|i| (p[i] / 2) as f32);
            let (mut k1, mut s1) = (keys, core::array::from_fn(|i| i as u32));
            let (mut k2, mut s2) = (keys, s1);
            sort_network_without(&mut k1, &mut s1, dropped);
            sort_insertion(&mut k2, &mut s2);
            wrong += usize::from((k1, s1) != (k2, s2));
        };
        check(&perm);
        let mut i = 0;
        while i < W {
            if c[i] < i {
                if i % 2 == 0 {
                    perm.swap(0, i);
                } else {
                    perm.swap(c[i], i);
                }
                check(&perm);
                c[i] += 1;
                i = 0;
            } else {
                c[i] = 0;
                i += 1;
            }
        }
        wrong
    }

    #[test]
    fn networks_sort_every_permutation_with_ties() {
        assert_eq!(wrong::<2>(usize::MAX), 0);
        assert_eq!(wrong::<4>(usize::MAX), 0);
        assert_eq!(wrong::<8>(usize::MAX), 0);
    }

    #[test]
    fn the_four_network_has_six_and_the_eight_network_twenty_four_compare_and_swaps_all_needed() {
        for dropped in 0..6 {
            assert!(wrong::<4>(dropped) > 0, "compare-and-swap {dropped} of 6 is not needed");
        }
        assert_eq!(wrong::<4>(6), 0, "there are only six");
        for dropped in 0..24 {
            assert!(wrong::<8>(dropped) > 0, "compare-and-swap {dropped} of 24 is not needed");
        }
        assert_eq!(wrong::<8>(24), 0, "there are only twenty-four");
    }
}
