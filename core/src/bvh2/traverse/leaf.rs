use crate::bvh2::{BvhMemory, NodeRef};
use crate::intersect::{RayContext, TriangleTest};
use crate::observe::Observer;
use crate::traverse::QueryState;

/// Tests the ray against every triangle of the leaf at `offset`.
///
/// Returns the three links of the leaf's termination entry and whether the leaf accepted a hit.
/// An any-hit query stops at its first hit (the links are then not read).
#[inline(always)]
pub fn intersect_leaf<M: BvhMemory + ?Sized, T: TriangleTest, O: Observer>(
    mem: &M,
    offset: u32,
    ctx: &RayContext<T>,
    q: &mut QueryState,
    obs: &mut O,
) -> ([NodeRef; 3], bool) {
    let mut o = offset;
    let mut accepted = false;
    let per_ray = ctx.tri();
    loop {
        let w0 = mem.read_leaf_word(o);
        if w0.is_terminator() {
            return (w0.links(), accepted);
        }
        let prim = w0.prim();
        obs.primitive(prim);
        let (w1, w2) = (mem.read_leaf_word(o + 1), mem.read_leaf_word(o + 2));
        let vertices = [w0.vertex_ref(), w1.vertex_ref(), w2.vertex_ref()];
        if let Some(h) = T::intersect_in_place(&per_ray, vertices, ctx.ray.tmin, q.limit()) {
            if q.offer(h, prim) {
                obs.hit(prim, h.t);
                accepted = true;
                if q.any {
                    return ([NodeRef::NONE; 3], true);
                }
            }
        }
        o += 3;
    }
}
