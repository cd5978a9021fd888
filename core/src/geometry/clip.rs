//! Bounds of the part of a triangle inside a box ("perfect splits", Havran 2000): the triangle is
//! clipped against the box planes (Sutherland-Hodgman) and the resulting polygon bounded.

use crate::geometry::Triangle;
use crate::Aabb;
use glam::Vec3;

/// A triangle clipped by the six planes of a box has at most nine vertices; rounding can make the
/// polygon slightly non-convex, so there is room for one more, and a polygon that would still
/// overflow falls back to the conservative answer.
const MAX_VERTICES: usize = 10;

type Vertices = [[f64; 3]; MAX_VERTICES];

/// Bounds of the part of `tri` inside the closed box `cell`, or `None` where the triangle misses
/// it. `tri_bounds` is `tri.bounds()`.
///
/// Conservative: the answer holds every point of the triangle inside `cell` (it may be a little
/// larger, never smaller) and lies inside `cell`. The clipping runs in `f64` against planes moved
/// outward by far more than its rounding error (a relative `2^-40`), so a triangle that only
/// touches the box, at a vertex or along an edge, is kept; the bounds are then rounded outward to
/// `f32` and cut to `cell`.
pub(crate) fn clipped_bounds(tri: &Triangle, tri_bounds: &Aabb, cell: &Aabb) -> Option<Aabb> {
    if misses(tri_bounds, cell) {
        return None;
    }
    if cell.contains(tri_bounds) {
        return Some(*tri_bounds);
    }
    let mut poly = Polygon::new(tri, cell);
    match poly.clip_to_box(tri_bounds, cell) {
        Step::Kept => Some(bounds(poly.vertices(), cell)),
        Step::Empty => None,
        Step::Overflow => Some(intersect(*tri_bounds, cell)),
    }
}

/// [`clipped_bounds`] for both children of a split of `cell` on `axis`: the box below (`cell`
/// with its upper face at `below_max`) and the one above (lower face at `above_min`). The
/// triangle is clipped to `cell` once, then that polygon against each child's face.
pub(crate) fn split_clipped_bounds(
    tri: &Triangle,
    tri_bounds: &Aabb,
    cell: &Aabb,
    axis: usize,
    below_max: f32,
    above_min: f32,
) -> (Option<Aabb>, Option<Aabb>) {
    let (mut below, mut above) = (*cell, *cell);
    below.max[axis] = below_max;
    above.min[axis] = above_min;
    if misses(tri_bounds, cell) {
        return (None, None);
    }
    let mut poly = Polygon::new(tri, cell);
    match poly.clip_to_box(tri_bounds, cell) {
        Step::Kept => {}
        Step::Empty => return (None, None),
        Step::Overflow => return (Some(intersect(*tri_bounds, &below)), Some(intersect(*tri_bounds, &above))),
    }
    split_polygon_bounds(poly.vertices(), poly.tol, axis, below_max, above_min, &below, &above)
}

/// [`split_clipped_bounds`] without clipping the triangle to `cell` first: the bounds of the
/// triangle's part on each side of the plane, cut to that side of `cell` (the reference split of
/// Stich et al. 2009). Conservative as [`split_clipped_bounds`] is, looser where the triangle
/// leaves `cell` elsewhere, and a few times cheaper: what a builder that splits at many planes
/// uses.
pub(crate) fn split_bounds(tri: &Triangle, cell: &Aabb, axis: usize, plane: f32) -> (Option<Aabb>, Option<Aabb>) {
    let (mut below, mut above) = (*cell, *cell);
    below.max[axis] = plane;
    above.min[axis] = plane;
    let vertices = tri.v.map(|p| [p.x as f64, p.y as f64, p.z as f64]);
    split_polygon_bounds(&vertices, tolerance(tri, cell), axis, plane, plane, &below, &above)
}

/// How far clipping planes move outward for `tri` and `cell`: interpolation in `f64` errs by a
/// few units of `2^-53` relative to the largest magnitude involved; this is `2^-40` of it.
fn tolerance(tri: &Triangle, cell: &Aabb) -> f64 {
    let scale = tri.v.iter().fold(cell.max_abs(), |m, v| m.max(v.abs().max_element()));
    scale as f64 * (1.0 / (1u64 << 40) as f64)
}

/// The bounds of the parts of polygon `poly` below `below_max` and above `above_min` on `axis`
/// (planes moved outward by `tol`), cut to the boxes `below` and `above`.
fn split_polygon_bounds(
    poly: &[[f64; 3]],
    tol: f64,
    axis: usize,
    below_max: f32,
    above_min: f32,
    below: &Aabb,
    above: &Aabb,
) -> (Option<Aabb>, Option<Aabb>) {
    (
        clipped_polygon_bounds(poly, axis, below_max as f64 + tol, true, below),
        clipped_polygon_bounds(poly, axis, above_min as f64 - tol, false, above),
    )
}

/// Whether boxes `a` and `b` are disjoint (closed boxes: touching is not missing).
fn misses(a: &Aabb, b: &Aabb) -> bool {
    a.max.cmplt(b.min).any() || a.min.cmpgt(b.max).any()
}

/// The part of two overlapping boxes common to both.
fn intersect(a: Aabb, b: &Aabb) -> Aabb {
    let min = a.min.max(b.min);
    Aabb { min, max: a.max.min(b.max).max(min) }
}

/// Outcome of clipping a polygon.
enum Step {
    /// Something is left.
    Kept,
    /// Nothing is left: the triangle misses the box.
    Empty,
    /// More vertices than [`MAX_VERTICES`]: callers fall back to the box cut of the triangle's
    /// bounds, which is conservative.
    Overflow,
}

/// A clip would exceed [`MAX_VERTICES`].
struct Overflow;

/// A triangle being clipped: a convex polygon in `f64`, in one of two buffers that clips
/// alternate between.
struct Polygon {
    buffers: [Vertices; 2],
    current: usize,
    len: usize,
    /// How far planes move outward: interpolation in `f64` errs by a few units of `2^-53`
    /// relative to the largest magnitude involved; this is `2^-40` of it.
    tol: f64,
}

impl Polygon {
    fn new(tri: &Triangle, cell: &Aabb) -> Self {
        let mut buffers = [[[0.0; 3]; MAX_VERTICES]; 2];
        for (p, v) in buffers[0].iter_mut().zip(tri.v) {
            *p = [v.x as f64, v.y as f64, v.z as f64];
        }
        Self { buffers, current: 0, len: 3, tol: tolerance(tri, cell) }
    }

    fn vertices(&self) -> &[[f64; 3]] {
        &self.buffers[self.current][..self.len]
    }

    /// Clips against the plane `p[axis] = plane` (see [`clip`]).
    fn clip(&mut self, axis: usize, plane: f64, upper: bool) -> Step {
        let [a, b] = &mut self.buffers;
        let (from, to) = if self.current == 0 { (&*a, b) } else { (&*b, a) };
        match clip(&from[..self.len], to, axis, plane, upper) {
            Ok(None) => Step::Kept,
            Ok(Some(0)) => Step::Empty,
            Ok(Some(n)) => {
                (self.current, self.len) = (1 - self.current, n);
                Step::Kept
            }
            Err(Overflow) => Step::Overflow,
        }
    }

    /// Clips to the faces of `cell` (moved outward by the tolerance) that cut the triangle's
    /// bounds `tri_bounds`.
    fn clip_to_box(&mut self, tri_bounds: &Aabb, cell: &Aabb) -> Step {
        for axis in 0..3 {
            if tri_bounds.min[axis] < cell.min[axis] {
                match self.clip(axis, cell.min[axis] as f64 - self.tol, false) {
                    Step::Kept => {}
                    other => return other,
                }
            }
            if tri_bounds.max[axis] > cell.max[axis] {
                match self.clip(axis, cell.max[axis] as f64 + self.tol, true) {
                    Step::Kept => {}
                    other => return other,
                }
            }
        }
        Step::Kept
    }
}

/// One Sutherland-Hodgman step: the part of the convex polygon `poly` on the inner side of the
/// plane `p[axis] = plane` (below it when `upper`, above otherwise; the plane itself counts as
/// inside). `Ok(None)`: all of it is inside (nothing written); `Ok(Some(n))`: `n` vertices
/// written to `out` (0: nothing inside).
fn clip(
    poly: &[[f64; 3]],
    out: &mut Vertices,
    axis: usize,
    plane: f64,
    upper: bool,
) -> Result<Option<usize>, Overflow> {
    let inside = |p: &[f64; 3]| if upper { p[axis] <= plane } else { p[axis] >= plane };
    let inner = poly.iter().filter(|p| inside(p)).count();
    if inner == poly.len() {
        return Ok(None);
    }
    if inner == 0 {
        return Ok(Some(0));
    }
    let mut n = 0;
    inner_part(poly, axis, plane, upper, |p| {
        *out.get_mut(n).ok_or(Overflow)? = *p;
        n += 1;
        Ok(())
    })?;
    Ok(Some(n))
}

/// Hands `emit` the vertices of the part of polygon `poly` on the inner side of the plane (see
/// [`clip`]), in order: each edge's crossing of the plane, exactly on it along `axis`, and each
/// vertex inside. Walks the edges (prev, cur), starting with the closing edge.
fn inner_part(
    poly: &[[f64; 3]],
    axis: usize,
    plane: f64,
    upper: bool,
    mut emit: impl FnMut(&[f64; 3]) -> Result<(), Overflow>,
) -> Result<(), Overflow> {
    let inside = |p: &[f64; 3]| if upper { p[axis] <= plane } else { p[axis] >= plane };
    let mut prev = &poly[poly.len() - 1];
    let mut prev_in = inside(prev);
    for cur in poly {
        let cur_in = inside(cur);
        if cur_in != prev_in {
            emit(&crossing(prev, cur, axis, plane))?;
        }
        if cur_in {
            emit(cur)?;
        }
        (prev, prev_in) = (cur, cur_in);
    }
    Ok(())
}

/// Where the edge `prev`-`cur` crosses the plane, placed exactly on it along `axis`.
#[inline]
fn crossing(prev: &[f64; 3], cur: &[f64; 3], axis: usize, plane: f64) -> [f64; 3] {
    let t = (plane - prev[axis]) / (cur[axis] - prev[axis]);
    let mut p = [0.0; 3];
    for k in 0..3 {
        p[k] = prev[k] + t * (cur[k] - prev[k]);
    }
    p[axis] = plane;
    p
}

/// [`bounds`] of what [`clip`] would give, without storing the polygon; `None` if nothing is
/// inside.
fn clipped_polygon_bounds(poly: &[[f64; 3]], axis: usize, plane: f64, upper: bool, cell: &Aabb) -> Option<Aabb> {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    // Growing bounds never overflows.
    let _ = inner_part(poly, axis, plane, upper, |p| {
        grow_bounds(&mut lo, &mut hi, p);
        Ok(())
    });
    (lo[0] <= hi[0]).then(|| rounded_bounds(lo, hi, cell))
}

/// Bounds of `poly` rounded outward to `f32` and cut to `cell` (the planes were moved outward, so
/// points may lie just outside it).
fn bounds(poly: &[[f64; 3]], cell: &Aabb) -> Aabb {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in poly {
        grow_bounds(&mut lo, &mut hi, p);
    }
    rounded_bounds(lo, hi, cell)
}

/// `[lo, hi]` grown to hold `p`. Plain comparisons: no NaN can occur, and `min`/`max` would
/// handle it.
#[inline(always)]
fn grow_bounds(lo: &mut [f64; 3], hi: &mut [f64; 3], p: &[f64; 3]) {
    for k in 0..3 {
        lo[k] = if p[k] < lo[k] { p[k] } else { lo[k] };
        hi[k] = if p[k] > hi[k] { p[k] } else { hi[k] };
    }
}

/// `[lo, hi]` rounded outward to `f32` and cut to `cell`.
fn rounded_bounds(lo: [f64; 3], hi: [f64; 3], cell: &Aabb) -> Aabb {
    let (min, max) = (cell.min.to_array(), cell.max.to_array());
    // Coordinates at or beyond a face (the clipped ones) are that face; only the others round.
    let down = |x: f64, k: usize| if x <= min[k] as f64 { min[k] } else { round_down(x).min(max[k]) };
    let up = |x: f64, k: usize| if x >= max[k] as f64 { max[k] } else { round_up(x).max(min[k]) };
    Aabb {
        min: Vec3::new(down(lo[0], 0), down(lo[1], 1), down(lo[2], 2)),
        max: Vec3::new(up(hi[0], 0), up(hi[1], 1), up(hi[2], 2)),
    }
}

/// The largest `f32` not above `x`.
pub(crate) fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x {
        next_down(f)
    } else {
        f
    }
}

/// The smallest `f32` not below `x`.
pub(crate) fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        next_up(f)
    } else {
        f
    }
}

/// The next `f32` towards `+inf` (`f32::next_up` needs a newer Rust than the workspace's floor).
pub(crate) fn next_up(x: f32) -> f32 {
    if x.is_nan() || x == f32::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f32::from_bits(1);
    }
    let b = x.to_bits();
    f32::from_bits(if x > 0.0 { b + 1 } else { b - 1 })
}

/// The next `f32` towards `-inf`.
pub(crate) fn next_down(x: f32) -> f32 {
    -next_up(-x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> Triangle {
        Triangle::new(Vec3::from(a), Vec3::from(b), Vec3::from(c))
    }

    fn clip(t: &Triangle, lo: [f32; 3], hi: [f32; 3]) -> Option<Aabb> {
        clipped_bounds(t, &t.bounds(), &Aabb::new(Vec3::from(lo), Vec3::from(hi)))
    }

    #[test]
    fn inside_is_unchanged_and_outside_is_none() {
        let t = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(clip(&t, [-1.0; 3], [2.0; 3]), Some(t.bounds()));
        assert_eq!(clip(&t, [2.0; 3], [3.0; 3]), None);
    }

    #[test]
    fn a_diagonal_triangle_is_clipped_tightly() {
        // The hypotenuse x + y = 1 cuts the corner box [0.5, 1]^2 only at (0.5, 0.5).
        let t = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let b = clip(&t, [0.5, 0.5, -1.0], [1.0, 1.0, 1.0]).unwrap();
        assert!((b.max.x - 0.5).abs() < 1e-6 && (b.max.y - 0.5).abs() < 1e-6, "{b:?}");
        // A box beyond the hypotenuse (but inside the triangle's bounds) is missed.
        assert_eq!(clip(&t, [0.6, 0.6, -1.0], [1.0, 1.0, 1.0]), None);
        // Cut at x <= 0.25: y still reaches 1.
        let b = clip(&t, [-1.0; 3], [0.25, 2.0, 2.0]).unwrap();
        assert_eq!((b.min.x, b.max.x, b.min.y, b.max.y), (0.0, 0.25, 0.0, 1.0));
    }

    #[test]
    fn touching_at_a_vertex_or_edge_is_kept() {
        let t = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let b = clip(&t, [1.0, -1.0, -1.0], [2.0, 1.0, 1.0]).unwrap();
        assert_eq!((b.min.x, b.max.x), (1.0, 1.0));
        assert!(b.max.y <= 1e-6 && b.min.y >= -1e-6, "{b:?}");
        let b = clip(&t, [-1.0, -1.0, 0.0], [2.0, 2.0, 1.0]).unwrap();
        assert_eq!((b.min.z, b.max.z), (0.0, 0.0));
    }

    #[test]
    fn split_clipping_matches_clipping_each_child() {
        let t = tri([0.0, 0.0, 0.0], [4.0, 1.0, 0.5], [1.0, 3.0, -0.5]);
        let cell = Aabb::new(Vec3::new(0.5, -1.0, -1.0), Vec3::new(3.5, 2.5, 1.0));
        for axis in 0..3 {
            let s = cell.center()[axis];
            let (below, above) = split_clipped_bounds(&t, &t.bounds(), &cell, axis, s, s);
            let (mut lo, mut hi) = (cell, cell);
            lo.max[axis] = s;
            hi.min[axis] = s;
            assert_eq!(below, clipped_bounds(&t, &t.bounds(), &lo));
            assert_eq!(above, clipped_bounds(&t, &t.bounds(), &hi));
        }
        // Missing one side.
        let (below, above) = split_clipped_bounds(&t, &t.bounds(), &cell, 1, -0.5, -0.5);
        assert!(below.is_none() && above.is_some());
    }

    #[test]
    fn splitting_without_clipping_holds_the_clipped_parts() {
        let t = tri([0.0, 0.0, 0.0], [4.0, 1.0, 3.0], [1.0, 4.0, -2.0]);
        let cell = Aabb::new(Vec3::new(0.5, 0.0, -1.0), Vec3::new(3.5, 3.0, 2.0));
        for plane in [0.75, 1.0, 2.0, 3.25] {
            let (loose_below, loose_above) = split_bounds(&t, &cell, 0, plane);
            let (tight_below, tight_above) = split_clipped_bounds(&t, &t.bounds(), &cell, 0, plane, plane);
            for (loose, tight) in [(loose_below, tight_below), (loose_above, tight_above)] {
                let (loose, tight) = (loose.unwrap(), tight.unwrap());
                assert!(loose.contains(&tight), "{loose:?} should hold {tight:?} at {plane}");
                assert!(cell.contains(&loose));
            }
            assert_eq!(loose_below.unwrap().max.x, plane);
            assert_eq!(loose_above.unwrap().min.x, plane);
        }
    }

    #[test]
    fn float_neighbours() {
        assert_eq!(next_up(1.0), f32::from_bits(1.0f32.to_bits() + 1));
        assert_eq!(next_down(1.0), f32::from_bits(1.0f32.to_bits() - 1));
        assert_eq!(next_up(-0.0), f32::from_bits(1));
        assert_eq!(next_down(0.0), -f32::from_bits(1));
        assert!((round_down(0.1) as f64) < 0.1 && (round_up(0.1) as f64) > 0.1);
        assert_eq!(round_up(0.1), next_up(round_down(0.1)));
        assert_eq!(round_up(f64::from(3.5f32)), 3.5);
    }
}
