// The point of the mesh nearest to a query point (`nearest::nearest_point_in`), after the wide
// tree's files: children nearest box first, a box farther than the best squared distance so far
// never entered, the point on each triangle by its region (`nearest::closest_point_on_triangle`:
// a vertex, an edge or the face). Its own work items, in place of entry.wgsl.
//
// A query comes as a `Ray` whose origin is the point in the scene's frame and whose tmax is the
// squared distance not to exceed (`nearest::query_bound`; negative: no answer). The answer is a
// `Hit` holding the squared distance for t, the triangle and the barycentrics (a miss: none within
// the bound), and the point in the query's `records` slot (three words). Products are rounded
// before they are added (`opq`) and quotients correctly rounded (`div_rn`), so that every distance
// is the CPU's bit for bit; the answer, the least (squared distance, primitive id) over the
// triangles within the bound, does not depend on the order children of one distance are visited in.

struct NearestEntry {
    child: u32,
    count: u32,
    d2: f32,
}

// Entries: every child of a node is pushed, at most WIDE_W on each of 64 levels.
const NP_STACK: u32 = WIDE_W * 64u;
var<private> NP_ENTRIES: array<NearestEntry, NP_STACK>;
var<private> NP_LEN: u32;
// The best point so far.
var<private> NP_POINT: vec3<f32>;

fn np_push(c: WideChild, d2: f32) {
    if NP_LEN < NP_STACK {
        NP_ENTRIES[NP_LEN] = NearestEntry(c.child, c.count, d2);
        NP_LEN = NP_LEN + 1u;
    }
}

// `Vec3::dot`: ((x + y) + z) of the rounded products.
fn np_dot(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return opq(a.x * b.x) + opq(a.y * b.y) + opq(a.z * b.z);
}

// `box_distance2`: the squared distance from `p` to child `i`'s box (0 inside it), the maxima by
// comparison (the float built-ins may flush a subnormal: numerics.wgsl).
fn np_box_distance2(node: u32, i: u32, p: vec3<f32>) -> f32 {
    let lo = vec3<f32>(bitcast<f32>(wide_word(node, i)), bitcast<f32>(wide_word(node, WIDE_W + i)),
        bitcast<f32>(wide_word(node, 2u * WIDE_W + i)));
    let hi = vec3<f32>(bitcast<f32>(wide_word(node, 3u * WIDE_W + i)),
        bitcast<f32>(wide_word(node, 4u * WIDE_W + i)), bitcast<f32>(wide_word(node, 5u * WIDE_W + i)));
    let below = lo - p;
    let above = p - hi;
    let m = select(above, below, below > above);
    let d = select(vec3<f32>(0.0), m, m > vec3<f32>(0.0));
    return np_dot(d, d);
}

// `PointOnTriangle`.
struct OnTriangle {
    u: f32,
    v: f32,
    point: vec3<f32>,
    d2: f32,
}

fn np_at(p: vec3<f32>, a: vec3<f32>, ab: vec3<f32>, ac: vec3<f32>, u: f32, v: f32) -> OnTriangle {
    let point = (a + opq3(ab * u)) + opq3(ac * v);
    let d = p - point;
    return OnTriangle(u, v, point, np_dot(d, d));
}

// The weight of `to` at the point of segment `from`-`to` nearest to `p` (`f32::clamp` to [0, 1]).
fn np_segment(p: vec3<f32>, from_v: vec3<f32>, to_v: vec3<f32>) -> f32 {
    let d = to_v - from_v;
    let len2 = np_dot(d, d);
    if !(len2 > 0.0) {
        return 0.0;
    }
    var w = div_rn(np_dot(p - from_v, d), len2);
    if w < 0.0 {
        w = 0.0;
    }
    if w > 1.0 {
        w = 1.0;
    }
    return w;
}

// `closest_point_on_triangle`, test for test.
fn np_closest(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> OnTriangle {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = np_dot(ab, ap);
    let d2 = np_dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return np_at(p, a, ab, ac, 0.0, 0.0);
    }
    let bp = p - b;
    let d3 = np_dot(ab, bp);
    let d4 = np_dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return np_at(p, a, ab, ac, 1.0, 0.0);
    }
    let vc = opq(d1 * d4) - opq(d3 * d2);
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return np_at(p, a, ab, ac, div_rn(d1, d1 - d3), 0.0);
    }
    let cp = p - c;
    let d5 = np_dot(ab, cp);
    let d6 = np_dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return np_at(p, a, ab, ac, 0.0, 1.0);
    }
    let vb = opq(d5 * d2) - opq(d1 * d6);
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return np_at(p, a, ab, ac, 0.0, div_rn(d2, d2 - d6));
    }
    let va = opq(d3 * d6) - opq(d5 * d4);
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = div_rn(d4 - d3, (d4 - d3) + (d5 - d6));
        return np_at(p, a, ab, ac, 1.0 - w, w);
    }
    let sum = va + vb + vc;
    if sum > 0.0 && is_finite(sum) {
        return np_at(p, a, ab, ac, div_rn(vb, sum), div_rn(vc, sum));
    }
    // No face to project onto: the nearest of the edges, the first of equal ones.
    let wbc = np_segment(p, b, c);
    var best = np_at(p, a, ab, ac, np_segment(p, a, b), 0.0);
    let on_ac = np_at(p, a, ab, ac, 0.0, np_segment(p, a, c));
    if on_ac.d2 < best.d2 {
        best = on_ac;
    }
    let on_bc = np_at(p, a, ab, ac, 1.0 - wbc, wbc);
    if on_bc.d2 < best.d2 {
        best = on_bc;
    }
    return best;
}

// `nearest_point_in` from bound `bound0`: the best hit (t: the squared distance), its point in
// NP_POINT.
fn np_walk(p: vec3<f32>, bound0: f32) -> Hit {
    var best = miss();
    var found = false;
    var bound = bound0;
    NP_LEN = 0u;
    np_push(wide_root(), 0.0);
    var budget = P.max_steps;
    loop {
        if NP_LEN == 0u {
            break;
        }
        NP_LEN = NP_LEN - 1u;
        let e = NP_ENTRIES[NP_LEN];
        if e.d2 > bound {
            continue;
        }
        if budget == 0u {
            break;
        }
        budget = budget - 1u;
        if e.count == 0u {
            // The children within the bound, farthest first, so that the nearest is popped next.
            var near_d: array<f32, WIDE_W>;
            var near_slot: array<u32, WIDE_W>;
            var n = 0u;
            for (var i = 0u; i < WIDE_W; i = i + 1u) {
                if !wide_slot(e.child, i).ok {
                    continue;
                }
                let d = np_box_distance2(e.child, i, p);
                if d <= bound {
                    var k = n;
                    loop {
                        if k == 0u || near_d[k - 1u] >= d {
                            break;
                        }
                        near_d[k] = near_d[k - 1u];
                        near_slot[k] = near_slot[k - 1u];
                        k = k - 1u;
                    }
                    near_d[k] = d;
                    near_slot[k] = i;
                    n = n + 1u;
                }
            }
            for (var k = 0u; k < n; k = k + 1u) {
                np_push(wide_slot(e.child, near_slot[k]).c, near_d[k]);
            }
        } else {
            for (var pos = e.child; pos < e.child + e.count; pos = pos + 1u) {
                let at = P.kd_tris / 4u + pos * 3u;
                let a = bvh[at];
                let on = np_closest(p, bitcast<vec3<f32>>(a.xyz), bitcast<vec3<f32>>(bvh[at + 1u].xyz),
                    bitcast<vec3<f32>>(bvh[at + 2u].xyz));
                let prim = a.w;
                var better = on.d2 <= bound;
                if found {
                    better = on.d2 < bound || (on.d2 == bound && prim < best.prim);
                }
                if better {
                    bound = on.d2;
                    best = Hit(on.d2, prim, on.u, on.v);
                    NP_POINT = on.point;
                    found = true;
                }
            }
        }
    }
    return best;
}

fn item_count() -> u32 {
    return P.ray_count;
}

fn run_item(i: u32) {
    let q = rays[i];
    NP_POINT = vec3<f32>(0.0);
    var h = miss();
    if q.tmax >= 0.0 {
        h = np_walk(q.origin, q.tmax);
    }
    hits[i] = h;
    let at = i * P.record_stride;
    records[at] = bitcast<u32>(NP_POINT.x);
    records[at + 1u] = bitcast<u32>(NP_POINT.y);
    records[at + 2u] = bitcast<u32>(NP_POINT.z);
}
