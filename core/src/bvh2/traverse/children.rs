use crate::bvh2::BinaryNode;
use crate::intersect::{BoxHit, RayContext, TriangleTest};

/// Where traversal goes from an internal node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Descent {
    /// Both child boxes missed.
    Neither,
    /// Only child `0` (left) or `1` (right) is hit.
    One(usize),
    /// Both hit: visit `first` now and postpone the other. `disjoint` when the t-intervals do not
    /// overlap (the first ends before the other starts, by more than the ray's `t_slack`), which
    /// the mask of Sec. 2.3 uses.
    Both {
        /// The closer child (ties go to the left).
        first: usize,
        /// Whether the two t-intervals are disjoint.
        disjoint: bool,
    },
}

/// Intersects the ray with both child boxes over `[tmin, limit]` (widened by the ray's slack, see
/// [`RayContext::box_interval`]) and orders them: the child with the smaller entry distance
/// first, ties to the left (the order every method shares).
#[inline(always)]
pub fn order_children<T: TriangleTest>(node: &BinaryNode, ctx: &RayContext<T>, limit: f32) -> Descent {
    let (lo, hi) = ctx.box_interval(limit);
    order(ctx.pair.hit_pair(node, lo, hi), ctx.t_slack)
}

/// The descent for the two child boxes' hits.
#[inline(always)]
fn order([left, right]: [Option<BoxHit>; 2], slack: f32) -> Descent {
    match (left, right) {
        (None, None) => Descent::Neither,
        (Some(_), None) => Descent::One(0),
        (None, Some(_)) => Descent::One(1),
        (Some(l), Some(r)) => {
            let (a, b) = if r.t_enter < l.t_enter { (r, l) } else { (l, r) };
            // The paper's test is `a.t_exit < b.t_enter`. A triangle's computed `t` can fall
            // outside its box's computed interval by rounding (a ray starting on a triangle's
            // plane, a direction near the float limits), and pruning on a bare comparison then
            // drops the true closest hit; the slack keeps the mask conservative. A NaN or
            // infinite slack makes nothing disjoint.
            Descent::Both { first: (r.t_enter < l.t_enter) as usize, disjoint: a.t_exit + slack < b.t_enter }
        }
    }
}
