use super::{encode_direct, HashShape};
use crate::bvh2::NodeRef;
use crate::Error;
use alloc::vec::Vec;

/// The two tables of a perfect hash over node keys.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PerfectHash {
    /// Table sizes.
    pub shape: HashShape,
    /// Displacement table `d` (size `D`): a displacement `>= 0`, or a node address directly
    /// (negative, see [`encode_direct`]).
    pub displacement: Vec<i32>,
    /// Hash table (size `H`): node addresses; empty cells hold [`NodeRef::NONE`].
    pub cells: Vec<u32>,
}

/// Figures of one construction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HashStats {
    /// Keys hashed.
    pub keys: usize,
    /// Keys served directly by their displacement entry (alone in their bucket).
    pub direct: usize,
    /// Displacement table size `D`.
    pub d_size: usize,
    /// Hash table size `H`.
    pub h_size: usize,
    /// Batches of buckets with equal dependency counts.
    pub batches: usize,
    /// Times the hash table was grown because a bucket could not be placed.
    pub growths: u32,
    /// Bytes of both tables.
    pub bytes: usize,
}

impl PerfectHash {
    /// Builds the tables for `(key, address)` entries of a tree of `node_count` nodes.
    ///
    /// Sizes follow Sec. 2.2.2: `D` is the largest power of two below half the node count, `H`
    /// the smallest odd number above twice it. Keys go to buckets `k mod D`; buckets are sorted by
    /// decreasing number of keys and placed batch by batch (equal counts together), each by a
    /// linear search for a displacement that puts all its keys in empty cells. A bucket of one key
    /// stores the address directly. Where no displacement fits, `H` grows (to `2H + 1`) and
    /// construction restarts, rather than searching forever.
    ///
    /// The paper places each batch in parallel on the GPU; here batches are placed one bucket at a
    /// time, which gives the same tables on every run.
    pub fn build(entries: &[(u64, NodeRef)], node_count: usize) -> Result<(PerfectHash, HashStats), Error> {
        let n = node_count.max(entries.len()).max(1);
        let mut d_size = 1usize;
        while 4 * d_size < n {
            d_size *= 2;
        }
        let mut h = 2 * n as u64 + 1;
        let d_mask = (d_size - 1) as u32;
        // Bucket of every entry, then buckets by decreasing size (ties by bucket index).
        let mut counts = alloc::vec![0u32; d_size];
        for &(k, _) in entries {
            counts[(k as u32 & d_mask) as usize] += 1;
        }
        let mut start = alloc::vec![0usize; d_size + 1];
        for b in 0..d_size {
            start[b + 1] = start[b] + counts[b] as usize;
        }
        let mut members = alloc::vec![(0u64, NodeRef::NONE); entries.len()];
        let mut fill = start.clone();
        for &e in entries {
            let b = (e.0 as u32 & d_mask) as usize;
            members[fill[b]] = e;
            fill[b] += 1;
        }
        let mut order: Vec<u32> = (0..d_size as u32).filter(|&b| counts[b as usize] > 0).collect();
        order.sort_by(|&a, &b| counts[b as usize].cmp(&counts[a as usize]).then(a.cmp(&b)));
        let batches = {
            let mut c: Vec<u32> = order.iter().map(|&b| counts[b as usize]).collect();
            c.dedup();
            c.len()
        };
        let mut growths = 0;
        'grow: loop {
            if h >= i32::MAX as u64 || h > 64 * n as u64 + 1024 {
                return Err(Error::HashConstruction { keys: entries.len(), table_size: h });
            }
            let mut displacement = alloc::vec![0i32; d_size];
            let mut cells = alloc::vec![NodeRef::NONE.0; h as usize];
            let mut direct = 0;
            let mut slots: Vec<u64> = Vec::new();
            let mut bases: Vec<u64> = Vec::new();
            for &b in &order {
                let bucket = &members[start[b as usize]..start[b as usize + 1]];
                if let [(_, addr)] = bucket {
                    displacement[b as usize] = encode_direct(*addr);
                    direct += 1;
                    continue;
                }
                // `(k + d) mod H` as `(k mod H + d) mod H`: one division per key, not per probe.
                bases.clear();
                bases.extend(bucket.iter().map(|&(k, _)| k % h));
                // Buckets start their search at spread-out displacements rather than all at 0,
                // which would crowd the cells just past each key's home slot.
                let first = (b as u64).wrapping_mul(0x9E37_79B9) % h;
                let mut placed = false;
                for i in 0..h {
                    let d = if first + i >= h { first + i - h } else { first + i };
                    slots.clear();
                    let fits = bases.iter().all(|&base| {
                        let s = if base + d >= h { base + d - h } else { base + d };
                        let free = cells[s as usize] == NodeRef::NONE.0 && !slots.contains(&s);
                        slots.push(s);
                        free
                    });
                    if fits {
                        for (&(_, addr), &s) in bucket.iter().zip(&slots) {
                            cells[s as usize] = addr.0;
                        }
                        displacement[b as usize] = d as i32;
                        placed = true;
                        break;
                    }
                }
                if !placed {
                    h = 2 * h + 1;
                    growths += 1;
                    continue 'grow;
                }
            }
            let shape = HashShape { d_mask, h: h as u32 };
            let bytes = 4 * (displacement.len() + cells.len());
            let stats = HashStats { keys: entries.len(), direct, d_size, h_size: h as usize, batches, growths, bytes };
            return Ok((PerfectHash { shape, displacement, cells }, stats));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh2::{BinaryNode, BvhMemory, LeafWord};
    use crate::hash::lookup;

    struct Tables<'a>(&'a PerfectHash);
    impl BvhMemory for Tables<'_> {
        fn node(&self, _: u32) -> BinaryNode {
            unreachable!()
        }
        fn leaf_word(&self, _: u32) -> LeafWord {
            unreachable!()
        }
        fn displacement(&self, slot: u32) -> i32 {
            self.0.displacement[slot as usize]
        }
        fn hash_cell(&self, slot: u32) -> u32 {
            self.0.cells[slot as usize]
        }
        fn hash_shape(&self) -> crate::hash::HashShape {
            self.0.shape
        }
    }

    fn check(entries: &[(u64, NodeRef)], nodes: usize) -> HashStats {
        let (ph, stats) = PerfectHash::build(entries, nodes).unwrap();
        assert_eq!(ph.shape.h % 2, 1, "H must be odd");
        assert!((ph.shape.d_mask as u64 + 1).is_power_of_two());
        for &(k, r) in entries {
            assert_eq!(lookup(&Tables(&ph), ph.shape, k).0, r, "key {k}");
            if k <= u32::MAX as u64 {
                assert_eq!(lookup(&Tables(&ph), ph.shape, k as u32).0, r, "u32 key {k}");
            }
        }
        stats
    }

    #[test]
    fn every_key_maps_to_its_address() {
        // Keys spread like those of an unbalanced tree, addresses mixing internal nodes and leaves.
        let entries: Vec<(u64, NodeRef)> = (1..1500u64)
            .map(|i| {
                (
                    i.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 30,
                    if i % 3 == 0 { NodeRef::leaf(i as u32 * 7) } else { NodeRef::internal(i as u32) },
                )
            })
            .collect();
        let s = check(&entries, 4000);
        assert_eq!(s.keys, 1499);
        assert!(s.direct > 0 && s.direct < s.keys, "{s:?}");
        assert_eq!(s.h_size, 8001);
        assert_eq!(s.d_size, 1024);
    }

    #[test]
    fn deep_keys_and_tiny_trees() {
        let deep: Vec<(u64, NodeRef)> =
            (0..500u64).map(|i| ((1u64 << 60) | (i * 0x9E37_79B9), NodeRef::internal(i as u32))).collect();
        check(&deep, 600);
        check(&[(2, NodeRef::leaf(0)), (3, NodeRef::leaf(4))], 3);
        check(&[], 1);
    }

    #[test]
    fn colliding_buckets_force_growth_not_a_hang() {
        // Every key in one bucket, congruent modulo the initial H: no displacement can separate
        // them until H grows.
        let h0 = 2 * 16 + 1;
        let entries: Vec<(u64, NodeRef)> = (0..3u64).map(|i| (64 * h0 * i + 64, NodeRef::internal(i as u32))).collect();
        let s = check(&entries, 16);
        assert!(s.growths > 0);
    }
}
