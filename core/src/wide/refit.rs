//! Refitting a wide tree: its child boxes taken again from the refitted binary tree, its
//! triangles from the moved scene, the collapse kept.
//!
//! A wide tree is a collapse of the canonical tree in which every child slot stands for one
//! canonical node (Guthe 2014, Sec. 4.1), and its box is that node's. Collapsing again after the
//! vertices moved could cut the tree elsewhere and order the slots otherwise (both go by box
//! areas), which would change node keys and make the hash over them stale; refitting keeps every
//! slot where it is and gives it its canonical node's new box.

use super::leaf_block::LeafBlock;
use super::tree::{canonical_of, WideBvh};
use crate::bvh2::refit::REFIT_CHUNK;
use crate::bvh2::Bvh2;
use crate::geometry::Triangle;
use crate::intersect::BLOCK;
use crate::stream::{Parallel, Serial};
use crate::Error;

impl<const W: usize> WideBvh<W> {
    /// Takes every child box from `bvh` (the canonical tree this one was collapsed from, refitted
    /// by [`Bvh2::refit`] to `triangles`) and every triangle from `triangles`, by primitive id.
    /// Linear in the tree's size; nodes, slots, leaf positions and keys are unchanged.
    ///
    /// [`Error::TreeMismatch`] when `bvh` or `triangles` is not the one this tree was made from
    /// (another node count, or a primitive id past the triangles); the tree is then unchanged.
    pub fn refit(&mut self, bvh: &Bvh2, triangles: &[Triangle]) -> Result<(), Error> {
        self.check_refit(bvh, triangles)?;
        self.refit_checked(bvh, triangles, &Serial);
        Ok(())
    }

    /// Whether [`WideBvh::refit`] to `bvh` and `triangles` can be done: every child names a node
    /// of `bvh` and every primitive id a triangle. Reads only this tree's id arrays (no box, no
    /// triangle), so that a caller may check everything before it changes anything, and refit in
    /// place rather than refit a copy.
    pub(crate) fn check_refit(&self, bvh: &Bvh2, triangles: &[Triangle]) -> Result<(), Error> {
        let mismatch = |why| Error::TreeMismatch { node: 0, why };
        if triangles.len() != bvh.prim_count() {
            return Err(mismatch("refit: the new triangle count differs from the tree's primitive count"));
        }
        let nodes = bvh.len();
        let (node_ids, leaf_ids) = self.canonical_ids();
        for node in self.nodes() {
            for child in (0..W).filter_map(|slot| node.child_ref(slot)) {
                let id = canonical_of(node_ids, leaf_ids, child.node_ref());
                if id.is_none_or(|id| id as usize >= nodes) {
                    return Err(mismatch("refit: a wide child names no node of the binary tree"));
                }
            }
        }
        if self.prims().iter().any(|&p| p != u32::MAX && p as usize >= triangles.len()) {
            return Err(mismatch("refit: a primitive id past the triangles"));
        }
        Ok(())
    }

    /// [`WideBvh::refit`] after [`WideBvh::check_refit`] passed (a child or primitive it would
    /// have refused is left as it is), each pass over nodes, triangles and blocks on `par`.
    pub(crate) fn refit_checked(&mut self, bvh: &Bvh2, triangles: &[Triangle], par: &impl Parallel) {
        let canonical = bvh.nodes();
        let (nodes, node_ids, leaf_ids) = self.boxes_mut();
        par.for_each_chunk(nodes, REFIT_CHUNK / W, |_, piece| {
            for node in piece {
                for slot in 0..W {
                    let Some(child) = node.child_ref(slot) else { continue };
                    let id = canonical_of(node_ids, leaf_ids, child.node_ref());
                    if let Some(b) = id.and_then(|id| canonical.get(id as usize)) {
                        node.set_child(slot, b.bounds.min, b.bounds.max, child);
                    }
                }
            }
        });
        let (tris, prims, blocks) = self.triangles_mut();
        par.for_each_chunk(tris, REFIT_CHUNK, |i, piece| {
            for (t, &p) in piece.iter_mut().zip(&prims[i * REFIT_CHUNK..]) {
                // The gaps between leaves (id u32::MAX) keep their NaN triangles.
                if let Some(moved) = triangles.get(p as usize) {
                    *t = *moved;
                }
            }
        });
        let tris = &*tris;
        let per_piece = REFIT_CHUNK / BLOCK;
        par.for_each_chunk(blocks, per_piece, |i, piece| {
            let at = i * REFIT_CHUNK;
            let (t, p) = (&tris[at.min(tris.len())..], &prims[at.min(prims.len())..]);
            for (block, (t, p)) in piece.iter_mut().zip(t.chunks(BLOCK).zip(p.chunks(BLOCK))) {
                *block = LeafBlock::new(t, p);
            }
        });
    }
}
