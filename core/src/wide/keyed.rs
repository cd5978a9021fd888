//! Node keys of a wide tree and the perfect hash that maps them to nodes: Binder & Keller's (2016)
//! keys carried from two children per node to `W`, for the stackless wide traversal
//! ([`super::trail`]).
//!
//! The root has key 1, and child slot `s` of the node keyed `k` has key `(k << b) | s`, with
//! `b = log2 W` bits per level ([`slot_bits`]): two for a 4-wide tree. The parent of `k` is
//! `k >> b` and its slot `k & (W - 1)`. A leaf at depth `d` (a child of the root: 1) has a key of
//! `1 + b d` bits, so 32-bit keys serve 4-wide trees of depth up to 15 and 64-bit keys up to 31
//! ([`wide_key_width`]).

use super::memory::WideMemory;
use super::node::WideNode;
use crate::bvh2::MemRead;
use crate::hash::{lookup_in, HashShape};
use crate::intersect::TriangleBlock;
use crate::key::{Key, KeyWidth};
use glam::Vec3;

/// Key bits per level of a `W`-wide tree (`W` a power of two): `log2 W`.
#[inline(always)]
pub const fn slot_bits<const W: usize>() -> u32 {
    W.trailing_zeros()
}

/// Key of child `slot` of the node keyed `key`.
#[inline(always)]
pub fn child_key<const W: usize, K: Key>(key: K, slot: u32) -> K {
    key.shl(slot_bits::<W>()) | K::from_u64(u64::from(slot))
}

/// The narrowest key width for a `W`-wide tree whose deepest leaf is at `depth`, or `None` where
/// even 64 bits are too few (a 4-wide tree deeper than 31 levels).
pub fn wide_key_width<const W: usize>(depth: u32) -> Option<KeyWidth> {
    let bits = 1 + u64::from(slot_bits::<W>()) * u64::from(depth);
    match bits {
        0..=32 => Some(KeyWidth::W32),
        33..=64 => Some(KeyWidth::W64),
        _ => None,
    }
}

/// The deepest a `W`-wide tree may be for 64-bit keys.
pub const fn max_keyed_depth<const W: usize>() -> u32 {
    63 / slot_bits::<W>()
}

/// A wide tree's memory with a perfect hash over its internal nodes' keys.
pub trait WideKeyedMemory<const W: usize>: WideMemory<W> {
    /// The index of the internal node keyed `key`, and whether the displacement entry held it
    /// (one load rather than two). Only keys of the tree's internal nodes may be asked for.
    fn keyed_node<K: Key>(&self, key: K) -> (u32, bool);
}

/// A wide tree in plain slices with its hash tables: the CPU and reference backends' memory for
/// the stackless wide traversal.
#[derive(Clone, Copy, Debug)]
pub struct WideHashedMemory<'a, M> {
    /// The tree.
    pub tree: M,
    /// Displacement table (see [`crate::hash`]).
    pub displacement: &'a [i32],
    /// Hash table cells: node references ([`crate::bvh2::NodeRef::internal`]).
    pub cells: &'a [u32],
    /// Table sizes.
    pub shape: HashShape,
}

impl<const W: usize, M: WideMemory<W>> WideMemory<W> for WideHashedMemory<'_, M> {
    const PREFETCHES: bool = M::PREFETCHES;
    #[inline(always)]
    fn wide_node(&self, index: u32) -> MemRead<'_, WideNode<W>> {
        self.tree.wide_node(index)
    }
    #[inline(always)]
    fn prim(&self, pos: u32) -> u32 {
        self.tree.prim(pos)
    }
    #[inline(always)]
    fn wide_triangle(&self, pos: u32) -> MemRead<'_, [Vec3; 3]> {
        self.tree.wide_triangle(pos)
    }
    #[inline(always)]
    fn wide_block(&self, index: u32) -> MemRead<'_, TriangleBlock> {
        self.tree.wide_block(index)
    }
    #[inline(always)]
    fn prefetch_child(&self, node: &WideNode<W>, slot: usize) {
        self.tree.prefetch_child(node, slot)
    }
}

impl<const W: usize, M: WideMemory<W>> WideKeyedMemory<W> for WideHashedMemory<'_, M> {
    #[inline(always)]
    fn keyed_node<K: Key>(&self, key: K) -> (u32, bool) {
        // A missing cell reads as node 0 rather than out of bounds: only a corrupt table asks.
        let d = |i: u32| self.displacement.get(i as usize).copied().unwrap_or(0);
        let c = |i: u32| self.cells.get(i as usize).copied().unwrap_or(0);
        let (r, direct) = lookup_in(d, c, self.shape, key);
        (r.index(), direct)
    }
}

/// The `(key, node)` entries of every internal node of `tree`, for [`crate::hash::PerfectHash`],
/// and the key width they need; [`crate::Error::TreeTooDeep`] past [`max_keyed_depth`].
#[cfg(feature = "alloc")]
pub fn keyed_nodes<const W: usize>(
    tree: &super::WideBvh<W>,
) -> Result<(alloc::vec::Vec<(u64, crate::bvh2::NodeRef)>, KeyWidth), crate::Error> {
    use super::node::WideChild;
    let depth = tree.stats().depth;
    let width = wide_key_width::<W>(depth).ok_or(crate::Error::TreeTooDeep { depth, max: max_keyed_depth::<W>() })?;
    let mut entries = alloc::vec::Vec::with_capacity(tree.nodes().len());
    let mut todo = alloc::vec::Vec::new();
    if let WideChild::Node(root) = tree.root() {
        todo.push((root, 1u64));
    }
    while let Some((index, key)) = todo.pop() {
        entries.push((key, crate::bvh2::NodeRef::internal(index)));
        let node = &tree.nodes()[index as usize];
        for slot in 0..W {
            if let Some(WideChild::Node(c)) = node.child_ref(slot) {
                todo.push((c, child_key::<W, u64>(key, slot as u32)));
            }
        }
    }
    Ok((entries, width))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_widths_follow_two_bits_per_level() {
        assert_eq!(slot_bits::<4>(), 2);
        assert_eq!(slot_bits::<8>(), 3);
        assert_eq!(wide_key_width::<4>(15), Some(KeyWidth::W32));
        assert_eq!(wide_key_width::<4>(16), Some(KeyWidth::W64));
        assert_eq!(wide_key_width::<4>(31), Some(KeyWidth::W64));
        assert_eq!(wide_key_width::<4>(32), None);
        assert_eq!(max_keyed_depth::<4>(), 31);
        assert_eq!(child_key::<4, u32>(1, 3), 0b111);
        assert_eq!(child_key::<4, u64>(0b110, 2), 0b11010);
    }

    #[cfg(feature = "alloc")]
    #[test]
    fn every_internal_node_gets_a_distinct_key_that_finds_it() {
        use crate::bvh2::SahBuilder;
        use crate::geometry::Triangle;
        use crate::hash::PerfectHash;
        use crate::method::Collapse;
        use crate::wide::WideBvh;
        let tris: alloc::vec::Vec<Triangle> = (0..300)
            .map(|i| {
                let (x, y) = ((i % 17) as f32, (i / 17) as f32);
                Triangle::new(Vec3::new(x, y, 0.0), Vec3::new(x + 1.0, y, 0.5), Vec3::new(x, y + 1.0, 1.0))
            })
            .collect();
        let bvh = SahBuilder::default().build(&tris).unwrap();
        let tree = WideBvh::<4>::build(&bvh, &tris, Collapse::PullUp).unwrap();
        let (entries, width) = keyed_nodes(&tree).unwrap();
        assert_eq!(entries.len(), tree.nodes().len());
        assert_eq!(Some(width), wide_key_width::<4>(tree.stats().depth));
        let (tables, _) = PerfectHash::build(&entries, tree.nodes().len()).unwrap();
        let mem = WideHashedMemory {
            tree: tree.memory(),
            displacement: &tables.displacement,
            cells: &tables.cells,
            shape: tables.shape,
        };
        for &(key, node) in &entries {
            assert_eq!(WideKeyedMemory::<4>::keyed_node(&mem, key).0, node.index(), "key {key:#b}");
        }
    }
}
