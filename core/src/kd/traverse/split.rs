use crate::intersect::SlabRay;
use crate::kd::KdNode;

/// Which children of an inner node a ray segment `[t_min, t_max]` enters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Crossing {
    /// Only the child the ray meets first.
    First(u32),
    /// Only the child the ray meets second.
    Second(u32),
    /// Both: `first` over `[t_min, t_split]`, then `second` over `[t_split, t_max]`.
    Both {
        /// The child met first.
        first: u32,
        /// The child met second.
        second: u32,
        /// Where the ray crosses the plane.
        t_split: f32,
    },
}

/// The one tie rule of every kd method (Horn et al. 2007, Appendix A, made exact).
///
/// Children are ordered by the direction's sign bit on the split axis (`+0` goes below first,
/// `-0` above first). With `t_split = (split - origin) * (1 / dir)`:
/// - `t_split >= t_max`: the segment ends before the plane: first child only;
/// - `t_split <= t_min`: it starts past the plane: second child only;
/// - otherwise both, split at `t_split`;
/// - `t_split` NaN (origin in the plane, direction parallel to it): first child only.
///
/// A segment touching the plane at one end thus enters one child, never a zero-length piece of
/// the other, so no leaf is visited twice. None is skipped because the builder puts every
/// triangle touching a plane into both children (closed half-spaces): a segment ending on the
/// plane, or lying in it, finds all such triangles on either side.
#[inline(always)]
pub fn cross(node: &KdNode, slab: &SlabRay, t_min: f32, t_max: f32) -> Crossing {
    let a = node.axis();
    // Indexed as arrays: glam's `Index` is a `match` on the axis, which compiled to branches
    // that the axes of successive nodes mispredict.
    let (origin, inv_dir): (&[f32; 3], &[f32; 3]) = (slab.origin.as_ref(), slab.inv_dir.as_ref());
    let t_split = (node.value - origin[a]) * inv_dir[a];
    let below = node.below();
    let (first, second) = if slab.negative[a] { (below + 1, below) } else { (below, below + 1) };
    if t_split >= t_max || t_split.is_nan() {
        Crossing::First(first)
    } else if t_split <= t_min {
        Crossing::Second(second)
    } else {
        Crossing::Both { first, second, t_split }
    }
}
