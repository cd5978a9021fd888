// The per-ray constants and the robust slab test (`intersect::{RayContext, SlabRay}`,
// `traverse::order_children`).

// The ray and its slab-test constants (`RayContext`, `SlabRay`).
struct Ctx {
    origin: vec3<f32>,
    tmin: f32,
    inv_dir: vec3<f32>,
    tmax: f32,
    // Per axis: the direction's sign bit is set (so -0 counts as negative).
    negative: vec3<bool>,
    // `RayContext::t_slack`, also the slab test's slack.
    t_slack: f32,
}

var<private> C: Ctx;

// `Ray::is_traceable`: finite origin and direction, a nonzero direction, an ordered interval.
fn is_traceable(r: Ray) -> bool {
    let finite = all(vec3<bool>(is_finite(r.origin.x), is_finite(r.origin.y), is_finite(r.origin.z)))
        && all(vec3<bool>(is_finite(r.dir.x), is_finite(r.dir.y), is_finite(r.dir.z)));
    return finite && any(r.dir != vec3<f32>(0.0)) && !is_nan(r.tmin) && !is_nan(r.tmax) && r.tmin <= r.tmax;
}

// `RayContext::new` for the slab part; returns `is_reliable()`.
fn ctx_init(r: Ray) -> bool {
    let reach = P.scene_scale + max_element(abs_bits3(r.origin));
    let inv_dir = div_rn3(vec3<f32>(1.0), r.dir);
    // 1 / max|d| exactly, as on the CPU: the smallest |1 / d_i|. It is subnormal for a direction
    // component near f32::MAX, hence the integer forms.
    let reach_per_d = reach * min_element_nonneg(abs_bits3(inv_dir));
    var slack = bitcast<f32>(0x7f800000u);
    if reach * reach * reach_per_d < bitcast<f32>(RELIABLE_LIMIT_BITS) {
        slack = reach_per_d * bitcast<f32>(SLACK_SCALE_BITS);
    }
    C.origin = r.origin;
    C.tmin = r.tmin;
    C.tmax = r.tmax;
    C.inv_dir = inv_dir;
    C.negative = vec3<bool>(sign_bit(r.dir.x), sign_bit(r.dir.y), sign_bit(r.dir.z));
    C.t_slack = slack;
    return is_finite(slack);
}

// Entry and exit distances of a box the ray hits (`BoxHit`), or `hit == false`.
struct BoxHit {
    hit: bool,
    t_enter: f32,
    t_exit: f32,
}

// `SlabRay::hit`: near/far planes by the sign bit; NaN candidates ignored; the far distance
// padded by FAR_PAD; accepted when `t_enter <= t_exit + slack`.
fn slab_hit(lo: vec3<f32>, hi: vec3<f32>, tmin: f32, tmax: f32) -> BoxHit {
    let near = select(lo, hi, C.negative);
    let far = select(hi, lo, C.negative);
    let tn = (near - C.origin) * C.inv_dir;
    let tf = (far - C.origin) * C.inv_dir * bitcast<f32>(FAR_PAD_BITS);
    let t_enter = keep_max(keep_max(keep_max(tmin, tn.x), tn.y), tn.z);
    let t_exit = opq(keep_min(keep_min(keep_min(tmax, tf.x), tf.y), tf.z));
    return BoxHit(t_enter <= t_exit + C.t_slack, t_enter, t_exit);
}

// `RayContext::box_interval`: `[tmin, limit]` widened by the slack on both ends.
fn box_interval(limit: f32) -> vec2<f32> {
    return vec2<f32>(C.tmin - C.t_slack, limit + C.t_slack);
}

// Where traversal goes from an internal node (`traverse::Descent`).
const DESCENT_NEITHER: u32 = 0u;
const DESCENT_ONE: u32 = 1u;
const DESCENT_BOTH: u32 = 2u;

struct Descent {
    kind: u32,
    // The only child hit (ONE) or the closer one (BOTH): 0 left, 1 right.
    first: u32,
    // BOTH: the t-intervals are disjoint by more than the slack.
    disjoint: bool,
}

// An internal node of the Aila-Laine layout: both child boxes, children, links.
struct Node {
    left_lo: vec3<f32>,
    left_hi: vec3<f32>,
    right_lo: vec3<f32>,
    right_hi: vec3<f32>,
    children: vec2<u32>,
    links: vec2<u32>,
}

fn load_node(index: u32) -> Node {
    let base = index * 4u;
    let l = bitcast<vec4<f32>>(bvh[base]);
    let r = bitcast<vec4<f32>>(bvh[base + 1u]);
    let z = bitcast<vec4<f32>>(bvh[base + 2u]);
    let w = bvh[base + 3u];
    return Node(vec3<f32>(l.x, l.z, z.x), vec3<f32>(l.y, l.w, z.y), vec3<f32>(r.x, r.z, z.z),
        vec3<f32>(r.y, r.w, z.w), w.xy, w.zw);
}

// `traverse::order_children`: both child boxes over the widened interval, the closer first,
// ties to the left.
fn order_children(n: Node, limit: f32) -> Descent {
    let iv = box_interval(limit);
    let l = slab_hit(n.left_lo, n.left_hi, iv.x, iv.y);
    let r = slab_hit(n.right_lo, n.right_hi, iv.x, iv.y);
    if !l.hit && !r.hit {
        return Descent(DESCENT_NEITHER, 0u, false);
    }
    if l.hit != r.hit {
        return Descent(DESCENT_ONE, select(0u, 1u, r.hit), false);
    }
    let right_first = r.t_enter < l.t_enter;
    var a = l;
    var b = r;
    if right_first {
        a = r;
        b = l;
    }
    // `a.t_exit` already went through `opq` in `slab_hit`.
    return Descent(DESCENT_BOTH, select(0u, 1u, right_first), a.t_exit + C.t_slack < b.t_enter);
}
