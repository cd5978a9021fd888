//! Ray sorting by compression, sorting and decompression (Garanzha & Loop 2010, Sec. 3.1, Fig.
//! 3-5): runs of equal keys are compressed to chunks, the chunks are radix-sorted by key, and the
//! sorted chunks are expanded back into a permutation of the rays.

use super::scan::{exclusive_scan, segmented_inclusive_scan};
use alloc::vec;
use alloc::vec::Vec;

/// Runs of equal keys: key, first position and length of each.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Chunks {
    /// The run's key (the paper's Chunk Hash).
    pub key: Vec<u32>,
    /// Its first position (Chunk Base).
    pub base: Vec<u32>,
    /// Its length (Chunk Size).
    pub size: Vec<u32>,
}

impl Chunks {
    /// Number of chunks.
    pub fn len(&self) -> usize {
        self.key.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.key.is_empty()
    }
}

/// Compression (Fig. 4): head flags where a key differs from the one before, their exclusive scan
/// as each run's slot, compaction of the runs' keys and bases into those slots, sizes as the
/// differences of consecutive bases. On one thread the exclusive scan of the head flags is the
/// count of runs met so far, so the slots are filled in one pass (a GPU runs the flags, the scan
/// and the scatter as three kernels, and gets the same arrays).
pub fn compress(keys: &[u32]) -> Chunks {
    let mut out = Chunks::default();
    for (i, &k) in keys.iter().enumerate() {
        if i == 0 || keys[i - 1] != k {
            out.key.push(k);
            out.base.push(i as u32);
        }
    }
    out.size = out
        .base
        .iter()
        .enumerate()
        .map(|(c, &b)| out.base.get(c + 1).copied().unwrap_or(keys.len() as u32) - b)
        .collect();
    out
}

/// A stable least-significant-digit radix sort of the chunks by key, eight bits a pass: chunks of
/// equal keys keep their order (by base), so the result is the one total order every backend
/// must reproduce.
pub fn radix_sort(chunks: &mut Chunks) {
    let n = chunks.len();
    let mut tmp = Chunks { key: vec![0; n], base: vec![0; n], size: vec![0; n] };
    for pass in 0..4 {
        let shift = 8 * pass;
        let mut counts = [0u32; 256];
        for &k in &chunks.key {
            counts[((k >> shift) & 0xff) as usize] += 1;
        }
        let (starts, _) = exclusive_scan(&counts);
        let mut next = starts;
        for i in 0..n {
            let digit = ((chunks.key[i] >> shift) & 0xff) as usize;
            let at = next[digit] as usize;
            next[digit] += 1;
            tmp.key[at] = chunks.key[i];
            tmp.base[at] = chunks.base[i];
            tmp.size[at] = chunks.size[i];
        }
        core::mem::swap(chunks, &mut tmp);
    }
}

/// Decompression (Fig. 5): the exclusive scan of the sorted chunks' sizes gives each chunk's
/// first sorted position; a skeleton of ones holds each chunk's base there, and the inclusive
/// segmented scan of the skeleton, segments headed by those positions, is the sorted order of
/// the `n` rays. On one thread that segmented scan writes each chunk's `base, base + 1, ...` in
/// turn, which is what this does in one pass (a GPU runs the scan, the skeleton and the
/// segmented scan as kernels, and gets the same array).
pub fn decompress(chunks: &Chunks, n: usize) -> Vec<u32> {
    let mut out = Vec::with_capacity(n);
    for (&base, &size) in chunks.base.iter().zip(&chunks.size) {
        out.extend(base..base + size);
    }
    out.truncate(n);
    out
}

/// The whole scheme: the sorted order of rays with these keys (stable: equal keys keep their
/// input order).
pub fn sort_by_key(keys: &[u32]) -> Vec<u32> {
    let mut chunks = compress(keys);
    radix_sort(&mut chunks);
    decompress(&chunks, keys.len())
}

/// Packet decomposition (Sec. 3.1, Fig. 6): the sorted keys compressed into cells, each cell cut
/// into packets of at most `max` rays (a scan of the packet counts, a skeleton of `max` headed by
/// each cell's base, its segmented scan). Returns the packets' first positions followed by the
/// number of rays, so packet `p` is `bounds[p]..bounds[p + 1]`.
pub fn packets(sorted_keys: &[u32], max: u32) -> Vec<u32> {
    let max = max.max(1);
    let cells = compress(sorted_keys);
    let per_cell: Vec<u32> = cells.size.iter().map(|s| s.div_ceil(max)).collect();
    let (first, total) = exclusive_scan(&per_cell);
    let mut skeleton = vec![max; total as usize];
    let mut heads = vec![false; total as usize];
    for (c, &f) in first.iter().enumerate() {
        skeleton[f as usize] = cells.base[c];
        heads[f as usize] = true;
    }
    segmented_inclusive_scan(&mut skeleton, &heads);
    skeleton.push(sorted_keys.len() as u32);
    skeleton
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's example (Fig. 3-5): twenty rays in six runs.
    const KEYS: [u32; 20] = [5, 5, 5, 1, 1, 1, 1, 3, 3, 2, 2, 2, 2, 2, 6, 6, 6, 4, 4, 4];

    #[test]
    fn compression_matches_the_papers_figure() {
        let c = compress(&KEYS);
        assert_eq!(c.base, [0, 3, 7, 9, 14, 17]);
        assert_eq!(c.size, [3, 4, 2, 5, 3, 3]);
    }

    #[test]
    fn the_sorted_order_is_stable_and_sorted() {
        let order = sort_by_key(&KEYS);
        assert_eq!(order, [3, 4, 5, 6, 9, 10, 11, 12, 13, 7, 8, 17, 18, 19, 0, 1, 2, 14, 15, 16]);
        // Against a plain stable sort, on keys with every byte in play and repeated runs.
        let mut rng = 0x1234_5678_u64;
        let keys: Vec<u32> = (0..5000)
            .map(|i| {
                rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                if i % 7 < 3 {
                    42
                } else {
                    (rng >> 32) as u32
                }
            })
            .collect();
        let mut expected: Vec<u32> = (0..keys.len() as u32).collect();
        expected.sort_by_key(|&i| keys[i as usize]);
        assert_eq!(sort_by_key(&keys), expected);
    }

    #[test]
    fn packets_split_cells_at_the_packet_size() {
        // Cells of 9, 5, 3 and 3 rays in packets of at most 4 (the paper's Fig. 6).
        let sorted = [[0u32; 9].as_slice(), &[1; 5], &[2; 3], &[3; 3]].concat();
        assert_eq!(packets(&sorted, 4), [0, 4, 8, 9, 13, 14, 17, 20]);
        assert_eq!(packets(&[], 4), [0]);
    }
}
