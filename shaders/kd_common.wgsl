// What every kd method shares (`kd::KdNode`, `kd::KdMemory`, `kd::traverse::{cross, kd_leaf,
// scene_interval}`): node access, the plane crossing with its one tie rule, the leaf test with its
// early exit, and the ray's segment inside the tree's box.

// SHORT_STACK_MAX (most entries a short stack may keep) comes in the generated header.

// Node `index` (`KdMemory::kd_node`): `x` the value's bits (split position, or a leaf's primitive
// count), `y` the word (axis or leaf tag 3 in bits 0-1, child or first reference above).
fn kd_node(index: u32) -> vec2<u32> {
    return vec2<u32>(kd[index * 2u], kd[index * 2u + 1u]);
}

fn kd_is_leaf(n: vec2<u32>) -> bool {
    return (n.y & 3u) == 3u;
}

// The vertices of primitive `prim` (`KdMemory::triangle`).
fn kd_vertex(prim: u32, corner: u32) -> vec3<f32> {
    let o = P.kd_tris + prim * 9u + corner * 3u;
    return bitcast<vec3<f32>>(vec3<u32>(kd[o], kd[o + 1u], kd[o + 2u]));
}

// A postponed child and its part of the segment: one stack entry of the single-ray methods.
struct KdEntry {
    node: u32,
    t_min: f32,
    t_max: f32,
}

// Which children of an inner node a segment enters (`Crossing`).
const CROSS_FIRST: u32 = 0u;
const CROSS_SECOND: u32 = 1u;
const CROSS_BOTH: u32 = 2u;

struct Crossing {
    kind: u32,
    // The child met first and the one met second (both set whatever `kind` is).
    first: u32,
    second: u32,
    // BOTH: where the ray crosses the plane.
    t_split: f32,
}

// `kd::traverse::cross` (named apart from WGSL's built-in `cross`): children ordered by the sign
// bit of the direction on the split axis; the segment ending on the plane or a NaN `t_split`
// (origin in the plane, direction parallel to it) takes the first child only, one starting on it
// the second only. `(split - origin) * inv_dir` cannot be contracted, so it needs no fence.
fn kd_cross(n: vec2<u32>, t_min: f32, t_max: f32) -> Crossing {
    let a = n.y & 3u;
    let t_split = (bitcast<f32>(n.x) - C.origin[a]) * C.inv_dir[a];
    let below = n.y >> 2u;
    var first = below;
    var second = below + 1u;
    if C.negative[a] {
        first = below + 1u;
        second = below;
    }
    if t_split >= t_max || is_nan(t_split) {
        return Crossing(CROSS_FIRST, first, second, t_split);
    }
    if t_split <= t_min {
        return Crossing(CROSS_SECOND, first, second, t_split);
    }
    return Crossing(CROSS_BOTH, first, second, t_split);
}

// `kd::traverse::kd_leaf`: tests every triangle of leaf `index`; returns whether traversal may
// stop: an any-hit query was answered, or the closest hit lies before the leaf's exit `t_max` by
// more than the slack, so no later leaf holds anything closer or tied.
fn kd_leaf(index: u32, n: vec2<u32>, t_max: f32) -> bool {
    rec_node(leaf_ref(index));
    let first = n.y >> 2u;
    let end = first + n.x;
    for (var i = first; i < end; i = i + 1u) {
        let prim = kd[P.kd_prims + i];
        rec_primitive();
        let h = tri_intersect(kd_vertex(prim, 0u), kd_vertex(prim, 1u), kd_vertex(prim, 2u), C.tmin, q_limit());
        if h.ok && q_offer(h, prim) && ANY_HIT {
            return true;
        }
    }
    return Q_HIT.prim != NO_PRIM && Q_HIT.t + C.t_slack < t_max;
}

// `kd::traverse::scene_interval`: the ray's segment inside the tree's box, over the ray's
// interval widened by the slack; `hit` false when it misses the box.
fn scene_interval() -> BoxHit {
    let iv = box_interval(C.tmax);
    return slab_hit(P.kd_lo.xyz, P.kd_hi.xyz, iv.x, iv.y);
}
