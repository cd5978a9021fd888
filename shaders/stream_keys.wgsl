// Ray hashing (`stream::ray_hash::RayGrid::key`): one invocation per ray.
//
// S.n: rays. S.v0: the origin grid's lower corner (xyz, f32 bits) and 1 / cell size (w);
// S.v1: origin cells per axis (xyz) and the origin Morton code's bits (w); S.v2: direction cells
// per face side, bits of a face position, the origin code's bits dropped to fit 32 bits.
// Binding 8: the keys (out).

@group(0) @binding(8) var<storage, read_write> keys: array<u32>;

// Rust's saturating `x as u32`: NaN and negatives to 0, beyond the range to u32::MAX. (WGSL's
// conversion of an out-of-range float is not pinned down.)
fn saturating_u32(x: f32) -> u32 {
    if !(x >= 1.0) {
        return 0u;
    }
    if x >= 4294967296.0 {
        return 0xffffffffu;
    }
    return u32(x);
}

fn spread3(x: u32) -> u32 {
    var v = x & 0x3ffu;
    v = (v | (v << 16u)) & 0x030000ffu;
    v = (v | (v << 8u)) & 0x0300f00fu;
    v = (v | (v << 4u)) & 0x030c30c3u;
    return (v | (v << 2u)) & 0x09249249u;
}

fn spread2(x: u32) -> u32 {
    var v = x & 0x3ffu;
    v = (v | (v << 8u)) & 0x00ff00ffu;
    v = (v | (v << 4u)) & 0x0f0f0f0fu;
    v = (v | (v << 2u)) & 0x33333333u;
    return (v | (v << 1u)) & 0x55555555u;
}

// `RayGrid::direction_cell`: the cube face, then the Morton-ordered position on it.
fn direction_cell(d: vec3<f32>) -> u32 {
    let a = abs_bits3(d);
    var axis = 2u;
    if a.x >= a.y && a.x >= a.z {
        axis = 0u;
    } else if a.y >= a.z {
        axis = 1u;
    }
    let face = 2u * axis + select(0u, 1u, sign_bit(d[axis]));
    let u = div_rn(d[(axis + 1u) % 3u], a[axis]);
    let v = div_rn(d[(axis + 2u) % 3u], a[axis]);
    let n = S.v2.x;
    let nf = f32(n);
    let cu = min(saturating_u32((u + 1.0) * 0.5 * nf), n - 1u);
    let cv = min(saturating_u32((v + 1.0) * 0.5 * nf), n - 1u);
    return (face << S.v2.y) | (spread2(cu) | (spread2(cv) << 1u));
}

fn ray_key(r: Ray) -> u32 {
    if !is_traceable(r) {
        return 0xffffffffu;
    }
    let lo = bitcast<vec3<f32>>(S.v0.xyz);
    let rel = (r.origin - lo) * bitcast<f32>(S.v0.w);
    let cx = min(saturating_u32(rel.x), S.v1.x - 1u);
    let cy = min(saturating_u32(rel.y), S.v1.y - 1u);
    let cz = min(saturating_u32(rel.z), S.v1.z - 1u);
    let origin = spread3(cx) | (spread3(cy) << 1u) | (spread3(cz) << 2u);
    let dir = direction_cell(r.dir);
    // The exact cell pair, the origin code's lowest `S.v2.z` bits dropped where the pair would
    // not fit 32 bits (`RayGrid::origin_drop`).
    let kept = S.v1.w - S.v2.z;
    let key = (dir << kept) | (origin >> S.v2.z);
    // The untraceable key is reserved.
    return min(key, 0xfffffffeu);
}

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = stream_item(gid);
    if i >= S.n {
        return;
    }
    keys[i] = ray_key(rays[i]);
}
