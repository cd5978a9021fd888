use crate::bvh2::NodeRef;
use crate::intersect::{KdRayContext, TriangleTest};
use crate::kd::{KdMemory, KdNode};
use crate::observe::Observer;
use crate::traverse::QueryState;

/// Tests the ray against every triangle of kd leaf `index` (a triangle may sit in several
/// leaves; it is tested in each, and the answer does not depend on where it is found first).
///
/// Returns whether traversal may stop after this leaf: an any-hit query was answered, or the
/// closest hit so far lies before the leaf's exit `t_max` by more than the ray's `t_slack`, so no
/// later leaf can hold anything closer or tied (Horn et al.'s early exit `tHit < tMax`, made
/// conservative against rounding in the triangle test).
#[inline(always)]
pub fn kd_leaf<M: KdMemory + ?Sized, T: TriangleTest, O: Observer>(
    mem: &M,
    index: u32,
    node: &KdNode,
    t_max: f32,
    ctx: &KdRayContext<T>,
    q: &mut QueryState,
    obs: &mut O,
) -> bool {
    obs.node(NodeRef::leaf(index));
    let per_ray = ctx.tri();
    for i in node.first()..node.first() + node.count() {
        let prim = mem.prim_ref(i);
        obs.primitive(prim);
        let tri = mem.read_triangle(prim);
        let [a, b, c] = &*tri;
        if let Some(h) = T::intersect_in_place(&per_ray, [a.as_ref(), b.as_ref(), c.as_ref()], ctx.ray.tmin, q.limit())
        {
            if q.offer(h, prim) {
                obs.hit(prim, h.t);
                if q.any {
                    return true;
                }
            }
        }
    }
    let hit = q.hit();
    hit.is_hit() && hit.t + ctx.t_slack < t_max
}
