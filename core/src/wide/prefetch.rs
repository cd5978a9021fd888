//! A wide tree in plain slices whose traversal asks the CPU to start loading every child a ray
//! hits, as soon as the node's box test has named them.
//!
//! On a tree far larger than the caches, an incoherent ray waits for memory at every visit, one
//! miss after another (`docs/notes/*-benchmarks-embree-gap.md`, "Prefetching the hit children").
//! Loading all hit children at once lets their misses overlap: the first child's while the
//! children are ordered and pushed, the pushed ones' while the first child's subtree is traversed.
//! Where the previous ray has already brought the nodes in (a tree that fits the caches, or
//! coherent rays in pixel order) the hints only cost instructions: shadow rays lost 12-15%. So the
//! CPU backend prefetches only where [`worth_prefetching`] says so.

use super::leaf_block::LeafBlock;
use super::memory::{WideMemory, WideSliceMemory};
use super::node::WideNode;
use crate::bvh2::MemRead;
use crate::intersect::{TriangleBlock, BLOCK};
use crate::method::Query;
use crate::Ray;
use glam::Vec3;

/// Trees of more bytes than this (nodes and triangle blocks) may be traversed with prefetching:
/// half of a 32 MB L3, well above the interiors (4-5 MB) where prefetching gained too little to
/// take (0.98-1.05 on diffuse rays), and well below the 871k-triangle dragon (45 MB) where it paid.
pub const PREFETCH_ABOVE_BYTES: usize = 16 << 20;

/// Whether a batch of `rays` answering `query` over a tree of `tree_bytes` (nodes and triangle
/// blocks) is traced faster with [`PrefetchingMemory`]: incoherent rays over a tree larger than
/// [`PREFETCH_ABOVE_BYTES`], closest-hit rays whether walked alone or together, any-hit rays only
/// together (`shared`: a method whose rays share walks, a packet method's, whose rays prefetch in
/// the subtrees handed over to them, or a stream method's, whose streams prefetch a node's hit
/// children for all the rays that hit them).
///
/// - Any-hit rays stop at their first occluder, often before the children fetched for them are
///   visited. Alone, on the dragon, ambient-occlusion rays gained 2-8% from outside but lost up to
///   6% from inside, so they go without. In packets they gained 7-15% from outside and moved by
///   0.94-1.00 from inside
///   (`docs/notes/*-benchmarks-packet-leaves.md`, "Prefetching in the packets' handed-over");
///   in streams 1.01-1.03 from outside and 1.00-1.02 from inside
///   (`docs/notes/*-benchmarks-stream-prefetch.md`, "Streams that prefetch").
/// - Incoherent: neighbouring rays that do not look coherent
///   ([`looks_coherent`](crate::trace_order::looks_coherent)), or the previous ray will have
///   brought the nodes in.
pub fn worth_prefetching(tree_bytes: usize, rays: &[Ray], query: Query, shared: bool) -> bool {
    if (query != Query::Closest && !shared) || tree_bytes <= PREFETCH_ABOVE_BYTES || rays.len() < 2 {
        return false;
    }
    !crate::trace_order::looks_coherent(rays)
}

/// Bytes of a cache line, the unit a prefetch brings in.
const LINE: usize = 64;

/// [`WideSliceMemory`] that prefetches hit children ([`WideMemory::prefetch_child`]).
#[derive(Clone, Copy, Debug)]
pub struct PrefetchingMemory<'a, const W: usize>(pub WideSliceMemory<'a, W>);

impl<const W: usize> WideMemory<W> for PrefetchingMemory<'_, W> {
    const PREFETCHES: bool = true;

    #[inline(always)]
    fn wide_node(&self, index: u32) -> MemRead<'_, WideNode<W>> {
        self.0.wide_node(index)
    }
    #[inline(always)]
    fn prim(&self, pos: u32) -> u32 {
        self.0.prim(pos)
    }
    #[inline(always)]
    fn wide_triangle(&self, pos: u32) -> MemRead<'_, [Vec3; 3]> {
        self.0.wide_triangle(pos)
    }
    #[inline(always)]
    fn wide_block(&self, index: u32) -> MemRead<'_, TriangleBlock> {
        self.0.wide_block(index)
    }

    /// The child's node, or its leaf's first block. The address is only
    /// formed, never read from, so an out-of-range child costs a useless hint and nothing else.
    #[inline(always)]
    fn prefetch_child(&self, node: &WideNode<W>, slot: usize) {
        let (child, count) = (node.child[slot % W] as usize, node.count[slot % W]);
        let (start, bytes) = if count == 0 {
            (self.0.nodes.as_ptr().wrapping_add(child).cast::<u8>(), core::mem::size_of::<WideNode<W>>())
        } else {
            (self.0.blocks.as_ptr().wrapping_add(child / BLOCK).cast::<u8>(), core::mem::size_of::<LeafBlock>())
        };
        // Every line the record touches, from the one its first byte is in (a 256-byte node that
        // does not start a line spans five).
        let line = start.wrapping_sub(start as usize % LINE);
        let end = start as usize % LINE + bytes;
        let mut offset = 0;
        while offset < end {
            hint(line.wrapping_add(offset));
            offset += LINE;
        }
    }
}

/// Asks the cache hierarchy for the line holding `at`; a no-op where the target has no stable
/// prefetch instruction.
#[inline(always)]
fn hint(at: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch never faults and changes no architectural state, whatever the address.
    unsafe {
        core::arch::x86_64::_mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>(at.cast::<i8>())
    };
    #[cfg(not(target_arch = "x86_64"))]
    let _ = at;
}
