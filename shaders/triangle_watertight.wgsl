// The watertight ray/triangle test of Woop, Benthin and Wald 2013 (`intersect::Watertight`):
// the same operations in the same order as the CPU, products fenced by `opq` against contraction,
// divisions correctly rounded, the f64 fallback for edge functions that come out 0 or tiny, and
// the f64 recomputation of hits whose first-order error bound is too large (core's
// intersect::refine, operation for operation).

// Per-ray constants: axis permutation (kz dominant) and shear.
struct TriRay {
    k: vec3<u32>,
    s: vec3<f32>,
    // The direction in the permuted order, for the f64 recomputation.
    d: vec3<f32>,
}

var<private> TR: TriRay;

// A triangle hit: `ok`, then t and barycentrics.
struct TriHit {
    ok: bool,
    t: f32,
    u: f32,
    v: f32,
}

fn tri_prepare(r: Ray) {
    let a = abs_bits3(r.dir);
    var kz = 2u;
    if a.x >= a.y && a.x >= a.z {
        kz = 0u;
    } else if a.y >= a.z {
        kz = 1u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    let dz = r.dir[kz];
    if dz < 0.0 {
        let t = kx;
        kx = ky;
        ky = t;
    }
    TR.k = vec3<u32>(kx, ky, kz);
    TR.s = vec3<f32>(div_rn(r.dir[kx], dz), div_rn(r.dir[ky], dz), div_rn(1.0, dz));
    TR.d = vec3<f32>(r.dir[kx], r.dir[ky], dz);
}

// `p * q - r * s` in f64, as the CPU's fallback (`exact_edges`): both products are exact in f64,
// so contraction cannot change it.
fn det2_f64(p: f32, q: f32, r: f32, s: f32) -> f64 {
    return f64(p) * f64(q) - f64(r) * f64(s);
}

// `intersect::watertight::mixed_signs`: the f64 edge functions are tested before they narrow to
// f32, where one below the f32 range would become a zero and lose its sign.
fn mixed_signs_f64(u: f64, v: f64, w: f64) -> bool {
    return (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0);
}

// `|x|` of an f64 by a comparison, not the float built-in (`abs_bits` is the f32 rule; these
// values, products of f32s, are normal f64s, so no flush can differ).
fn magnitude_f64(x: f64) -> f64 {
    return select(-x, x, x >= 0.0);
}

// `intersect::refine::needs_refine`: whether the f32 hit may be more than REFINE_ULPS ulps off, to
// first order. `a`, `b`, `c` are the vertices relative to the origin (original axis order).
fn tri_needs_refine(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, ax: f32, ay: f32, bx: f32, by: f32, cx: f32, cy: f32,
                    az: f32, bz: f32, cz: f32, t: f32, det: f32) -> bool {
    let kx = TR.k.x;
    let ky = TR.k.y;
    let kz = TR.k.z;
    let ma = (abs_bits(a[kx]) + abs_bits(a[ky])) + (abs_bits(a[kz]) + abs_bits(a[kz]));
    let mb = (abs_bits(b[kx]) + abs_bits(b[ky])) + (abs_bits(b[kz]) + abs_bits(b[kz]));
    let mc = (abs_bits(c[kx]) + abs_bits(c[ky])) + (abs_bits(c[kz]) + abs_bits(c[kz]));
    let sa = abs_bits(ax) + abs_bits(ay);
    let sb = abs_bits(bx) + abs_bits(by);
    let sc = abs_bits(cx) + abs_bits(cy);
    let eu = (opq(mb * sc) + opq(mc * sb)) + opq(sb * sc);
    let ev = (opq(mc * sa) + opq(ma * sc)) + opq(sc * sa);
    let ew = (opq(ma * sb) + opq(mb * sa)) + opq(sa * sb);
    let lhs = (opq(eu * abs_bits(az - t)) + opq(ev * abs_bits(bz - t))) + opq(ew * abs_bits(cz - t));
    return lhs > bitcast<f32>(REFINE_SCALE_BITS) * abs_bits(t * det);
}

// `x - 0` with a zero the compiler cannot see (the uniform `P.zero`): exact, the sign of a zero
// kept, and a wall no algebraic rewrite crosses. Every f64 product of the recomputation goes
// through it (`xmul`). Exact products alone are not enough: Mesa's compiler (lavapipe) fuses a
// product into the next addition as an FMA and then factors an operand shared by two products of
// one sum out of them (`a*b + a*c` into `a*(b + c)`); `b + c` then has more than 24 bits, the
// product is no longer exact, and the last bit of an edge function moved (one ulp of `v` on the
// cornell box, enough to flip the sign of a `t` that is exactly 0).
fn opq64(x: f64) -> f64 {
    return x - f64(bitcast<f32>(P.zero));
}

// The exact f64 product of two f32 values, fenced by `opq64`.
fn xmul(a: f64, b: f64) -> f64 {
    return opq64(a * b);
}

// `x` as the sum of two f32 values (`intersect::refine::split`).
fn split64(x: f64) -> vec2<f64> {
    let hi = f32(x);
    return vec2<f64>(f64(hi), f64(f32(x - f64(hi))));
}

// Products of split parts only, each exact in f64 and fenced (`mul2`).
fn mul2_64(p: vec2<f64>, q: vec2<f64>) -> f64 {
    return xmul(p.x, q.x) + (xmul(p.x, q.y) + xmul(p.y, q.x));
}

// `px qy - py qx` of split sheared coordinates (`edge`).
fn edge64(px: vec2<f64>, py: vec2<f64>, qx: vec2<f64>, qy: vec2<f64>) -> f64 {
    let lead = xmul(px.x, qy.x) - xmul(py.x, qx.x);
    return lead + ((xmul(px.x, qy.y) + xmul(px.y, qy.x)) - (xmul(py.x, qx.y) + xmul(py.y, qx.x)));
}

// A vertex relative to the origin, in ray axis order, each coordinate split.
struct Rel64 {
    x: vec2<f64>,
    y: vec2<f64>,
    z: vec2<f64>,
}

fn rel64(p: vec3<f32>) -> Rel64 {
    let o = C.origin;
    return Rel64(
        split64(f64(p[TR.k.x]) - f64(o[TR.k.x])),
        split64(f64(p[TR.k.y]) - f64(o[TR.k.y])),
        split64(f64(p[TR.k.z]) - f64(o[TR.k.z])),
    );
}

// `intersect::refine::inverse_scale`: 2^-e for a normal x with 2^e <= |x| < 2^(e+1), else 1, as
// the exact product of two f32 powers of two.
fn inverse_scale64(x: f32) -> f64 {
    let e = i32((bitcast<u32>(x) >> 23u) & 0xffu);
    if e == 0 || e == 255 {
        return 1.0;
    }
    let k = 127 - e;
    // Floor division by 2 (k may be negative).
    let half = (k - select(0, 1, k < 0 && (k & 1) != 0)) / 2;
    let p0 = f64(bitcast<f32>(u32(half + 127) << 23u));
    let p1 = f64(bitcast<f32>(u32(k - half + 127) << 23u));
    return xmul(p0, p1);
}

// The sheared coordinates times dz, split: `((dz x - dx z) + dz x_lo) - dx z_lo`, the direction
// scaled by `scale` (so that 1 <= |dz| < 2).
fn shear64(p: Rel64, scale: f64) -> array<vec2<f64>, 2> {
    let dx = xmul(f64(TR.d.x), scale);
    let dy = xmul(f64(TR.d.y), scale);
    let dz = xmul(f64(TR.d.z), scale);
    let x = ((xmul(dz, p.x.x) - xmul(dx, p.z.x)) + xmul(dz, p.x.y)) - xmul(dx, p.z.y);
    let y = ((xmul(dz, p.y.x) - xmul(dy, p.z.x)) + xmul(dz, p.y.y)) - xmul(dy, p.z.y);
    return array<vec2<f64>, 2>(split64(x), split64(y));
}

// `intersect::refine::refine`: the hit recomputed in f64; `ok` false where a value leaves the f32
// range (the caller keeps its f32 hit).
fn tri_refine(a0: vec3<f32>, b0: vec3<f32>, c0: vec3<f32>) -> TriHit {
    let ra = rel64(a0);
    let rb = rel64(b0);
    let rc = rel64(c0);
    // The direction scaled to 1 <= |dz| < 2, as on the CPU (a dz far from 1 would leave the
    // denominator subnormal in f32).
    let scale = inverse_scale64(TR.d.z);
    let a = shear64(ra, scale);
    let b = shear64(rb, scale);
    let c = shear64(rc, scale);
    let u = edge64(c[0], c[1], b[0], b[1]);
    let w = edge64(b[0], b[1], a[0], a[1]);
    let v = edge64(a[0], a[1], c[0], c[1]);
    // The f64 edge functions disagree with the f32 hit: the f32 hit stands (as on the CPU).
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return TriHit(false, 0.0, 0.0, 0.0);
    }
    let det = (u + v) + w;
    let num = (mul2_64(split64(u), ra.z) + mul2_64(split64(v), rb.z)) + mul2_64(split64(w), rc.z);
    let d = split64(det);
    let dz = xmul(f64(TR.d.z), scale);
    let den = xmul(d.x, dz) + xmul(d.y, dz);
    let num32 = f32(num);
    let den32 = f32(den);
    let det32 = f32(det);
    let v32 = f32(v);
    let w32 = f32(w);
    if !(is_finite(num32) && is_finite(den32) && is_finite(det32) && is_finite(v32) && is_finite(w32))
        || den32 == 0.0 || det32 == 0.0 {
        return TriHit(false, 0.0, 0.0, 0.0);
    }
    let t = f32(xmul(f64(div_rn(num32, den32)), scale));
    return TriHit(true, t, div_rn(v32, det32), div_rn(w32, det32));
}

fn tri_intersect(a0: vec3<f32>, b0: vec3<f32>, c0: vec3<f32>, tmin: f32, tmax: f32) -> TriHit {
    let no = TriHit(false, 0.0, 0.0, 0.0);
    let kx = TR.k.x;
    let ky = TR.k.y;
    let kz = TR.k.z;
    let a = a0 - C.origin;
    let b = b0 - C.origin;
    let c = c0 - C.origin;
    let ax = a[kx] - opq(TR.s.x * a[kz]);
    let ay = a[ky] - opq(TR.s.y * a[kz]);
    let bx = b[kx] - opq(TR.s.x * b[kz]);
    let by = b[ky] - opq(TR.s.y * b[kz]);
    let cx = c[kx] - opq(TR.s.x * c[kz]);
    let cy = c[ky] - opq(TR.s.y * c[kz]);
    var u = opq(cx * by) - opq(cy * bx);
    var v = opq(ax * cy) - opq(ay * cx);
    var w = opq(bx * ay) - opq(by * ax);
    // Whether the first-order error bound applies (not to rescaled edge functions).
    var bounded = true;
    let tiny = bitcast<f32>(TINY_EDGE_BITS);
    if abs_bits(u) < tiny || abs_bits(v) < tiny || abs_bits(w) < tiny {
        var u64 = det2_f64(cx, by, cy, bx);
        var v64 = det2_f64(ax, cy, ay, cx);
        var w64 = det2_f64(bx, ay, by, ax);
        if mixed_signs_f64(u64, v64, w64) {
            return no;
        }
        // `intersect::watertight::narrow_edges`: scaled up by EDGE_STEP until the largest is at
        // least 1 / EDGE_STEP (powers of two: exact), so that none underflows when narrowed.
        let step = f64(bitcast<f32>(EDGE_STEP_BITS));
        let floor = 1.0 / step;
        var largest = max(max(magnitude_f64(u64), magnitude_f64(v64)), magnitude_f64(w64));
        if largest < floor && largest != 0.0 {
            bounded = false;
            for (var i = 0u; i < 4u && largest < floor; i++) {
                u64 = u64 * step;
                v64 = v64 * step;
                w64 = w64 * step;
                largest = largest * step;
            }
        }
        u = f32(u64);
        v = f32(v64);
        w = f32(w64);
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return no;
    }
    let det = u + v + w;
    if det == 0.0 {
        return no;
    }
    let az = TR.s.z * a[kz];
    let bz = TR.s.z * b[kz];
    let cz = TR.s.z * c[kz];
    let t = div_rn(opq(u * az) + opq(v * bz) + opq(w * cz), det);
    if !is_finite(t) || t < tmin {
        return no;
    }
    var hit = TriHit(true, t, div_rn(v, det), div_rn(w, det));
    // Decided before tmax is looked at, as on the CPU: tmax depends on the traversal order.
    if bounded && tri_needs_refine(a, b, c, ax, ay, bx, by, cx, cy, az, bz, cz, t, det) {
        let r = tri_refine(a0, b0, c0);
        if r.ok {
            hit = r;
        }
        if !is_finite(hit.t) || hit.t < tmin {
            return no;
        }
    }
    if hit.t > tmax {
        return no;
    }
    return hit;
}
