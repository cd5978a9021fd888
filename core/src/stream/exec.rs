//! How a stage maps over its items.

/// How a stage maps over its items: one after another ([`Serial`]), or in parallel where a
/// backend supplies a pool (the CPU backend's rayon). Every stage's result is the same either way,
/// which is what lets the serial reference check a parallel backend array by array.
pub trait Parallel: Sync {
    /// `f(0), f(1), ..., f(n - 1)`, in that order.
    fn map<T: Send>(&self, n: usize, f: impl Fn(usize) -> T + Sync + Send) -> alloc::vec::Vec<T>;

    /// Sorts chunks by key, equal keys by base: the order the stable radix sort of
    /// [`radix_sort`](super::sort::radix_sort) gives, which is the default. Since no two chunks
    /// share a base, any correct sort by (key, base) gives the same result.
    fn sort_chunks(&self, chunks: &mut super::sort::Chunks) {
        super::sort::radix_sort(chunks);
    }

    /// `f(i, piece)` for each piece `i` of `data` cut into `chunk` items (the last may be
    /// shorter), in any order and possibly at once: for passes that write each item from data
    /// they only read, such as a refit's ([`crate::prepared::PreparedScene::refit_with`]).
    fn for_each_chunk<T: Send>(&self, data: &mut [T], chunk: usize, f: impl Fn(usize, &mut [T]) + Sync + Send) {
        for (i, piece) in data.chunks_mut(chunk.max(1)).enumerate() {
            f(i, piece);
        }
    }
}

/// Every item on the calling thread.
#[derive(Clone, Copy, Debug, Default)]
pub struct Serial;

impl Parallel for Serial {
    fn map<T: Send>(&self, n: usize, f: impl Fn(usize) -> T + Sync + Send) -> alloc::vec::Vec<T> {
        (0..n).map(f).collect()
    }
}
