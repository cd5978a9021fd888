// Ray hashing (`stream::ray_hash::RayGrid::key`): one invocation per ray.
//
// S.n: rays. S.v0: the origin grid's lower corner (xyz, f32 bits) and 1 / cell size (w);
// S.v1: origin cells per axis (xyz) and the origin Morton code's bits (w); S.v2: direction cells
// per face side, bits of a face position, whether the cell pair is the key as it is (1) or mixed.
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

// 64-bit words as (low, high) pairs of u32, for the mixing function.
fn add64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.x + b.x;
    return vec2<u32>(lo, a.y + b.y + select(0u, 1u, lo < a.x));
}

// The full 64-bit product of two u32, from 16-bit halves.
fn mul_wide(a: u32, b: u32) -> vec2<u32> {
    let al = a & 0xffffu;
    let ah = a >> 16u;
    let bl = b & 0xffffu;
    let bh = b >> 16u;
    let p0 = al * bl;
    let p1 = al * bh;
    let p2 = ah * bl;
    let p3 = ah * bh;
    let mid = (p0 >> 16u) + (p1 & 0xffffu) + (p2 & 0xffffu);
    return vec2<u32>((mid << 16u) | (p0 & 0xffffu), p3 + (p1 >> 16u) + (p2 >> 16u) + (mid >> 16u));
}

// `wrapping_mul` of two 64-bit words.
fn mul64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let low = mul_wide(a.x, b.x);
    return vec2<u32>(low.x, low.y + a.x * b.y + a.y * b.x);
}

// `z ^ (z >> s)` for 0 < s < 32.
fn xorshift64(z: vec2<u32>, s: u32) -> vec2<u32> {
    return z ^ vec2<u32>((z.x >> s) | (z.y << (32u - s)), z.y >> s);
}

// `ray_hash::mix`: the splitmix64 finalizer, low 32 bits.
fn mix64(id: vec2<u32>) -> u32 {
    var z = add64(id, vec2<u32>(0x7f4a7c15u, 0x9e3779b9u));
    z = mul64(xorshift64(z, 30u), vec2<u32>(0x1ce4e5b9u, 0xbf58476du));
    z = mul64(xorshift64(z, 27u), vec2<u32>(0x133111ebu, 0x94d049bbu));
    return xorshift64(z, 31u).x;
}

// `RayGrid::direction_cell`: the cube face, then the Morton-ordered position on it.
fn direction_cell(d: vec3<f32>) -> u32 {
    let a = abs(d);
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
    let bits = S.v1.w;
    // `(dir << bits) | origin` as a 64-bit word (bits is at most 30).
    var high = 0u;
    if bits > 0u {
        high = dir >> (32u - bits);
    }
    let id = vec2<u32>((dir << bits) | origin, high);
    var key = id.x;
    if S.v2.z == 0u {
        key = mix64(id);
    }
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
