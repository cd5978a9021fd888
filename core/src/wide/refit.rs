//! Refitting a wide tree: its child boxes taken again from the refitted binary tree, its
//! triangles from the moved scene, the collapse kept.
//!
//! A wide tree is a collapse of the canonical tree in which every child slot stands for one
//! canonical node (Guthe 2014, Sec. 4.1), and its box is that node's. Collapsing again after the
//! vertices moved could cut the tree elsewhere and order the slots otherwise (both go by box
//! areas), which would change node keys and make the hash over them stale; refitting keeps every
//! slot where it is and gives it its canonical node's new box.

use super::leaf_block::LeafBlock;
use super::node::WideChild;
use super::tree::WideBvh;
use crate::bvh2::Bvh2;
use crate::geometry::Triangle;
use crate::intersect::BLOCK;
use crate::Error;

impl<const W: usize> WideBvh<W> {
    /// Takes every child box from `bvh` (the canonical tree this one was collapsed from, refitted
    /// by [`Bvh2::refit`] to `triangles`) and every triangle from `triangles`, by primitive id.
    /// Linear in the tree's size; nodes, slots, leaf positions and keys are unchanged.
    ///
    /// [`Error::TreeMismatch`] when `bvh` or `triangles` is not the one this tree was made from
    /// (another node count, or a primitive id past the triangles).
    pub fn refit(&mut self, bvh: &Bvh2, triangles: &[Triangle]) -> Result<(), Error> {
        let mismatch = |why| Error::TreeMismatch { node: 0, why };
        if triangles.len() != bvh.prim_count() {
            return Err(mismatch("refit: the new triangle count differs from the tree's primitive count"));
        }
        let canonical = bvh.nodes();
        let (nodes, node_ids, leaf_ids) = self.boxes_mut();
        for node in nodes.iter_mut() {
            for slot in 0..W {
                let id = match node.child_ref(slot) {
                    None => continue,
                    Some(WideChild::Node(n)) => node_ids.get(n as usize),
                    Some(WideChild::Leaf { first, .. }) => leaf_ids.get(first as usize),
                };
                let b = id
                    .and_then(|&id| canonical.get(id as usize))
                    .ok_or(mismatch("refit: a wide child names no node of the binary tree"))?
                    .bounds;
                let child = node.child_ref(slot).ok_or(mismatch("refit: an empty slot"))?;
                node.set_child(slot, b.min, b.max, child);
            }
        }
        let (tris, prims, blocks) = self.triangles_mut();
        for (t, &p) in tris.iter_mut().zip(prims.iter()) {
            // The gaps between leaves (id u32::MAX) keep their NaN triangles.
            if p != u32::MAX {
                *t = *triangles.get(p as usize).ok_or(mismatch("refit: a primitive id past the triangles"))?;
            }
        }
        for (block, (t, p)) in blocks.iter_mut().zip(tris.chunks(BLOCK).zip(prims.chunks(BLOCK))) {
            *block = LeafBlock::new(t, p);
        }
        Ok(())
    }
}
