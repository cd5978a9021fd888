//! The point of a triangle nearest to a given point, by the region the point projects into
//! (Ericson, *Real-Time Collision Detection*, 2005, Sec. 5.1.5): one of the three vertices, one of
//! the three edges, or the face. Dot products only, no square root, in `f32`.

use glam::Vec3;

/// Where on a triangle the nearest point lies, as barycentric weights of its second (`u`) and
/// third (`v`) vertex, with the point and its squared distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointOnTriangle {
    /// Weight of the second vertex.
    pub u: f32,
    /// Weight of the third vertex.
    pub v: f32,
    /// The point, `a + u (b - a) + v (c - a)`.
    pub point: Vec3,
    /// Squared distance from the query point.
    pub distance2: f32,
}

/// The point of triangle `(a, b, c)` nearest to `p`. A degenerate triangle (its vertices on a
/// line or in one point) is treated as the segments between its vertices.
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> PointOnTriangle {
    let (ab, ac) = (b - a, c - a);
    let at = |u: f32, v: f32| {
        let point = a + ab * u + ac * v;
        PointOnTriangle { u, v, point, distance2: (p - point).length_squared() }
    };
    // Projections of p onto the edges from each vertex decide the vertex regions, and the signed
    // areas of the sub-triangles (products of them) the edge regions.
    let ap = p - a;
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return at(0.0, 0.0);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return at(1.0, 0.0);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return at(d1 / (d1 - d3), 0.0);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return at(0.0, 1.0);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return at(0.0, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return at(1.0 - w, w);
    }
    let sum = va + vb + vc;
    if sum > 0.0 && sum.is_finite() {
        return at(vb / sum, vc / sum);
    }
    // No face to project onto (zero area, or products out of range): the nearest of the edges.
    let segment = |from: Vec3, to: Vec3| {
        let d = to - from;
        let len2 = d.length_squared();
        if len2 > 0.0 {
            ((p - from).dot(d) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        }
    };
    let (wab, wac, wbc) = (segment(a, b), segment(a, c), segment(b, c));
    let candidates = [at(wab, 0.0), at(0.0, wac), at(1.0 - wbc, wbc)];
    candidates.into_iter().fold(candidates[0], |best, x| if x.distance2 < best.distance2 { x } else { best })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nearest point by brute force in `f64`: a fine grid of barycentric points.
    fn sampled(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f64 {
        let n = 200;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let q: [f64; 3] =
                    core::array::from_fn(|k| f64::from(a[k]) + u * f64::from(b[k] - a[k]) + v * f64::from(c[k] - a[k]));
                let d: f64 = (0..3).map(|k| (q[k] - f64::from(p[k])).powi(2)).sum();
                best = best.min(d);
            }
        }
        best
    }

    #[test]
    fn every_region_gives_the_nearest_point() {
        let (a, b, c) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.5));
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 6.0 - 3.0
        };
        for _ in 0..300 {
            let p = Vec3::new(next(), next(), next());
            let got = closest_point_on_triangle(p, a, b, c);
            let want = sampled(p, a, b, c);
            assert!(f64::from(got.distance2) <= want + 1e-4, "{p}: {got:?} vs {want}");
            assert!(f64::from(got.distance2) >= want - 0.02 * want.sqrt() - 1e-4, "{p}: {got:?} vs {want}");
            assert!(got.u >= 0.0 && got.v >= 0.0 && got.u + got.v <= 1.0 + 1e-6, "{got:?}");
        }
        // Each region once, exactly.
        assert_eq!(closest_point_on_triangle(Vec3::new(-1.0, -1.0, 0.0), a, b, c).point, a);
        assert_eq!(closest_point_on_triangle(Vec3::new(3.0, -1.0, 0.0), a, b, c).point, b);
        assert_eq!(closest_point_on_triangle(Vec3::new(1.0, -1.0, 0.0), a, b, c).point, Vec3::new(1.0, 0.0, 0.0));
        // Above the face point at u = v = 1/4, (0.5, 0.25, 0.125), along the normal (0, -1, 2).
        let inside = closest_point_on_triangle(Vec3::new(0.5, -0.25, 1.125), a, b, c);
        assert!((inside.u - 0.25).abs() < 1e-6 && (inside.v - 0.25).abs() < 1e-6, "{inside:?}");
    }

    #[test]
    fn a_degenerate_triangle_is_its_segments() {
        let (a, b, c) = (Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0));
        let got = closest_point_on_triangle(Vec3::new(1.5, 1.0, 0.0), a, b, c);
        assert_eq!((got.point, got.distance2), (Vec3::new(1.5, 0.0, 0.0), 1.0));
        let point = closest_point_on_triangle(Vec3::new(0.0, 2.0, 0.0), Vec3::ONE, Vec3::ONE, Vec3::ONE);
        assert_eq!((point.point, point.distance2), (Vec3::ONE, 3.0));
    }
}
