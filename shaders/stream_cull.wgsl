// The frustum-box test (`stream::FrustumCull::overlaps`): the segments' box, the span along the
// dominant axis, then the four side planes at both ends of the box's overlap with the span. The
// plane bound is `near + (far - near) * s` with the product fenced, as on the CPU.

fn plane_at(f: Frustum, k: u32, s: f32) -> f32 {
    return f.near_rect[k] + opq((f.far_rect[k] - f.near_rect[k]) * s);
}

fn frustum_overlaps(f: Frustum, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    if f.active_rays == 0u {
        return false;
    }
    if any(hi < f.lo) || any(lo > f.hi) {
        return false;
    }
    if f.axis == NO_AXIS {
        return true;
    }
    let a = f.axis;
    let x0 = rust_max(lo[a], f.near);
    let x1 = rust_min(hi[a], f.far);
    if x0 > x1 {
        return false;
    }
    let s0 = (x0 - f.near) * f.inv_span;
    let s1 = (x1 - f.near) * f.inv_span;
    for (var side = 0u; side < 4u; side = side + 2u) {
        let axis = (a + 1u + side / 2u) % 3u;
        let lower = rust_min(plane_at(f, side, s0), plane_at(f, side, s1));
        let upper = rust_max(plane_at(f, side + 1u, s0), plane_at(f, side + 1u, s1));
        // Below the lower plane at both ends, or above the upper plane at both ends.
        if hi[axis] < lower || lo[axis] > upper {
            return false;
        }
    }
    return true;
}
