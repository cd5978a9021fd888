// Packet frustums (`stream::Frustum::build`): one invocation per packet, the same IEEE operations
// in the same order as the core, so the frustum comes out bit for bit: products that feed an
// addition fenced with `opq`, divisions by `div_rn`, glam's and Rust's min/max conventions.
//
// S.n: packets. S.v0.xyz, S.v1.xyz: the scene box (f32 bits). Binding 8: the rays' sorted order;
// 9: packet bounds (S.n + 1); 10: the frustums (out). STREAM_MARGIN_BITS and NO_AXIS come in the
// generated header.

@group(0) @binding(8) var<storage, read_write> order: array<u32>;
@group(0) @binding(9) var<storage, read_write> bounds: array<u32>;
@group(0) @binding(10) var<storage, read_write> frustums: array<Frustum>;

// An active ray's segment inside the scene box over its widened interval (`frustum::Segment`).
struct Segment {
    ok: bool,
    p0: vec3<f32>,
    p1: vec3<f32>,
    d: vec3<f32>,
    reach: f32,
}

fn segment(r: Ray) -> Segment {
    var s: Segment;
    s.ok = false;
    // `begin_slab`: traceable, with a finite slack.
    if !is_traceable(r) || !ctx_init(r) {
        return s;
    }
    let iv = box_interval(r.tmax);
    let h = slab_hit(bitcast<vec3<f32>>(S.v0.xyz), bitcast<vec3<f32>>(S.v1.xyz), iv.x, iv.y);
    if !h.hit {
        return s;
    }
    s.ok = true;
    s.p0 = r.origin + opq3(r.dir * h.t_enter);
    s.p1 = r.origin + opq3(r.dir * h.t_exit);
    s.d = r.dir;
    s.reach = P.scene_scale + max_element(abs_bits3(r.origin));
    return s;
}

fn empty_frustum() -> Frustum {
    return Frustum(vec3<f32>(0.0), NO_AXIS, vec3<f32>(0.0), 0u, 0.0, 0.0, 0.0, 0u, vec4<f32>(0.0), vec4<f32>(0.0));
}

fn build(first: u32, end: u32) -> Frustum {
    let inf = bitcast<f32>(0x7f800000u);
    var live = 0u;
    var lo = vec3<f32>(inf);
    var hi = vec3<f32>(-inf);
    var mean = vec3<f32>(0.0);
    var reach = 0.0;
    var min_share = vec3<f32>(inf);
    var positive = vec3<bool>(false);
    var negative = vec3<bool>(false);
    for (var j = first; j < end; j = j + 1u) {
        let s = segment(rays[order[j]]);
        if !s.ok {
            continue;
        }
        live = live + 1u;
        lo = glam_min(lo, glam_min(s.p0, s.p1));
        hi = glam_max(hi, glam_max(s.p0, s.p1));
        let dmax = max_element(abs_bits3(s.d));
        mean = mean + div_rn3(s.d, vec3<f32>(dmax));
        reach = rust_max(reach, s.reach);
        for (var a = 0u; a < 3u; a = a + 1u) {
            min_share[a] = rust_min(min_share[a], div_rn(abs_bits(s.d[a]), dmax));
            // A zero component counts as both signs.
            positive[a] = positive[a] || s.d[a] >= 0.0;
            negative[a] = negative[a] || s.d[a] <= 0.0;
        }
    }
    if live == 0u {
        return empty_frustum();
    }
    // A power of two: exact.
    let m = reach * bitcast<f32>(STREAM_MARGIN_BITS);
    lo = lo - vec3<f32>(m);
    hi = hi + vec3<f32>(m);
    let dir_signs = select(0u, 1u, mean.x < 0.0) | (select(0u, 1u, mean.y < 0.0) << 1u)
        | (select(0u, 1u, mean.z < 0.0) << 2u);
    var f = empty_frustum();
    f.lo = lo;
    f.hi = hi;
    f.active_rays = live;
    f.dir_signs = dir_signs;
    let finite = is_finite(lo.x) && is_finite(lo.y) && is_finite(lo.z) && is_finite(hi.x) && is_finite(hi.y)
        && is_finite(hi.z);
    if !finite {
        f.lo = vec3<f32>(-inf);
        f.hi = vec3<f32>(inf);
        return f;
    }
    // The dominant axis: one sign for every ray, the largest smallest share, a later axis wins ties.
    var axis = NO_AXIS;
    for (var a = 0u; a < 3u; a = a + 1u) {
        if positive[a] != negative[a] && (axis == NO_AXIS || min_share[a] >= min_share[axis]) {
            axis = a;
        }
    }
    if axis == NO_AXIS || !(min_share[axis] >= 0.25) {
        return f;
    }
    let b = (axis + 1u) % 3u;
    let c = (axis + 2u) % 3u;
    let near = lo[axis];
    let far = hi[axis];
    var n = vec4<f32>(inf, -inf, inf, -inf);
    var fr = n;
    for (var j = first; j < end; j = j + 1u) {
        let s = segment(rays[order[j]]);
        if !s.ok {
            continue;
        }
        for (var e = 0u; e < 2u; e = e + 1u) {
            let x = select(near, far, e == 1u);
            let k = div_rn(x - s.p0[axis], s.d[axis]);
            let u = s.p0[b] + opq(k * s.d[b]);
            let v = s.p0[c] + opq(k * s.d[c]);
            var r = select(n, fr, e == 1u);
            r = vec4<f32>(rust_min(r.x, u), rust_max(r.y, u), rust_min(r.z, v), rust_max(r.w, v));
            if e == 0u {
                n = r;
            } else {
                fr = r;
            }
        }
    }
    f.axis = axis;
    f.near = near;
    f.far = far;
    f.inv_span = 0.0;
    if far > near {
        f.inv_span = div_rn(1.0, far - near);
    }
    f.near_rect = vec4<f32>(n.x - m, n.y + m, n.z - m, n.w + m);
    f.far_rect = vec4<f32>(fr.x - m, fr.y + m, fr.z - m, fr.w + m);
    return f;
}

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let p = stream_item(gid);
    if p >= S.n {
        return;
    }
    frustums[p] = build(bounds[p], bounds[p + 1u]);
}
