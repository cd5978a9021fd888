// Arithmetic that comes out bit for bit as on the CPU, whatever the shader compiler does.
// Why each piece exists is documented in one place: backends/wgpu/NUMERICS.md.

// Returns `x` unchanged through an integer operation with a zero the compiler cannot see
// (`P.zero`). A product passed through it is rounded to f32 before it is added to anything: SPIR-V
// and other targets allow `a * b + c` to be contracted into a fused multiply-add, which rounds
// once instead of twice and changes low bits.
fn opq(x: f32) -> f32 {
    return bitcast<f32>(bitcast<u32>(x) ^ P.zero);
}

fn opq3(v: vec3<f32>) -> vec3<f32> {
    return bitcast<vec3<f32>>(bitcast<vec3<u32>>(v) ^ vec3<u32>(P.zero));
}

// `|x|` by clearing the sign bit. On an H100 (driver 580) the float absolute value or minimum
// flushed a subnormal to zero even in SPIR-V kernels that preserve subnormals, which the CPU never
// does (backends/wgpu/NUMERICS.md, section 3); an integer operation cannot flush.
fn abs_bits(x: f32) -> f32 {
    return bitcast<f32>(bitcast<u32>(x) & 0x7fffffffu);
}

fn abs_bits3(v: vec3<f32>) -> vec3<f32> {
    return bitcast<vec3<f32>>(bitcast<vec3<u32>>(v) & vec3<u32>(0x7fffffffu));
}

// The smallest component of a vector of non-negative floats, none NaN, compared as integers: for
// such floats the bit patterns order as the values do, subnormals included (see `abs_bits`).
fn min_element_nonneg(v: vec3<f32>) -> f32 {
    let b = bitcast<vec3<u32>>(v);
    return bitcast<f32>(min(min(b.x, b.y), b.z));
}

// `max(acc, x)` keeping `acc` when `x` is NaN or equal (`intersect::keep_max`).
fn keep_max(acc: f32, x: f32) -> f32 {
    return select(acc, x, x > acc);
}

// `min(acc, x)` keeping `acc` when `x` is NaN or equal (`intersect::keep_min`).
fn keep_min(acc: f32, x: f32) -> f32 {
    return select(acc, x, x < acc);
}

// `glam::Vec3::max_element`: `max(x, max(y, z))` with `if a > b { a } else { b }`.
fn max_element(v: vec3<f32>) -> f32 {
    let yz = select(v.z, v.y, v.y > v.z);
    return select(yz, v.x, v.x > yz);
}

fn sign_bit(x: f32) -> bool {
    return (bitcast<u32>(x) >> 31u) == 1u;
}

fn is_nan(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7fffffffu) > 0x7f800000u;
}

fn is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// The normalized significand (bit 23 set) and unbiased-exponent-plus-127 of a nonzero finite
// float's magnitude bits; subnormals are normalized, so their exponent goes below 1.
fn unpack_significand(bits: u32) -> vec2<i32> {
    let e = i32((bits >> 23u) & 0xffu);
    let m = bits & 0x7fffffu;
    if e != 0 {
        return vec2<i32>(i32(m | 0x800000u), e);
    }
    let shift = i32(countLeadingZeros(m)) - 8;
    return vec2<i32>(i32(m << u32(shift)), 1 - shift);
}

// One step of restoring long division: the next quotient bit of remainder `qr.y` over `den`.
fn div_bit(qr: vec2<u32>, den: u32) -> vec2<u32> {
    let take = qr.y >= den;
    let r = select(qr.y, qr.y - den, take);
    return vec2<u32>((qr.x << 1u) | select(0u, 1u, take), r << 1u);
}

// Five steps of `div_bit`, written out.
fn div_bits5(qr: vec2<u32>, den: u32) -> vec2<u32> {
    return div_bit(div_bit(div_bit(div_bit(div_bit(qr, den), den), den), den), den);
}

// `a / b` correctly rounded to nearest even, as IEEE 754 and the CPU divide. WGSL's `/` is only
// accurate to 2.5 ulp on Vulkan, so the quotient is computed with integers: special cases, then a
// 25-bit long division of the significands (no loop) with a sticky bit, then rounding (to a subnormal where
// the exponent is too small).
fn div_rn(a: f32, b: f32) -> f32 {
    let ua = bitcast<u32>(a);
    let ub = bitcast<u32>(b);
    let sign = (ua ^ ub) & 0x80000000u;
    let ma = ua & 0x7fffffffu;
    let mb = ub & 0x7fffffffu;
    let nan = 0x7fc00000u;
    if ma > 0x7f800000u || mb > 0x7f800000u {
        return bitcast<f32>(nan);
    }
    if ma == 0x7f800000u {
        return bitcast<f32>(select(sign | 0x7f800000u, nan, mb == 0x7f800000u));
    }
    if mb == 0x7f800000u {
        return bitcast<f32>(sign);
    }
    if mb == 0u {
        return bitcast<f32>(select(sign | 0x7f800000u, nan, ma == 0u));
    }
    if ma == 0u {
        return bitcast<f32>(sign);
    }
    let na = unpack_significand(ma);
    let nb = unpack_significand(mb);
    var num = u32(na.x);
    let den = u32(nb.x);
    var e = na.y - nb.y + 127;
    if num < den {
        num = num << 1u;
        e = e - 1;
    }
    // Quotient in [1, 2): 24 significand bits and one guard bit, five bits per call and no
    // loop (llvmpipe silently cuts loops that run too long in total, see backends/wgpu/NUMERICS.md).
    var qr = vec2<u32>(0u, num);
    qr = div_bits5(qr, den);
    qr = div_bits5(qr, den);
    qr = div_bits5(qr, den);
    qr = div_bits5(qr, den);
    qr = div_bits5(qr, den);
    let q = qr.x;
    var sticky = qr.y != 0u;
    // Bits of `q` below the result's last significand bit: 1 for a normal result, more below.
    var drop = 1u;
    if e < 1 {
        drop = u32(min(1 - e, 30)) + 1u;
        e = 0;
    }
    let kept = q >> drop;
    let round_bit = (q >> (drop - 1u)) & 1u;
    sticky = sticky || (q & ((1u << (drop - 1u)) - 1u)) != 0u;
    var m = kept + select(0u, 1u, round_bit == 1u && (sticky || (kept & 1u) == 1u));
    if e == 0 {
        // Subnormal (a carry into bit 23 makes it the smallest normal, which the bits spell).
        return bitcast<f32>(sign | m);
    }
    if m == 0x1000000u {
        m = m >> 1u;
        e = e + 1;
    }
    if e >= 255 {
        return bitcast<f32>(sign | 0x7f800000u);
    }
    return bitcast<f32>(sign | (u32(e) << 23u) | (m & 0x7fffffu));
}

fn div_rn3(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(div_rn(a.x, b.x), div_rn(a.y, b.y), div_rn(a.z, b.z));
}

// A float's bits as an unsigned integer in the floats' order (negatives below positives, `-0`
// just below `+0`), so that `atomicMin` over the integers takes the least float; the packet and
// stream walks keep each child's least entry distance this way.
fn order_bits(t: f32) -> u32 {
    let b = bitcast<u32>(t);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

// The float whose `order_bits` are `k`.
fn from_order_bits(k: u32) -> f32 {
    return bitcast<f32>(select(~k, k & 0x7fffffffu, (k & 0x80000000u) != 0u));
}
