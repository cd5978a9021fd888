// The watertight ray/triangle test of Woop, Benthin and Wald 2013 (`intersect::Watertight`):
// the same operations in the same order as the CPU, products fenced by `opq` against contraction,
// divisions correctly rounded, and the f64 fallback for edge functions that come out exactly 0.

// Per-ray constants: axis permutation (kz dominant) and shear.
struct TriRay {
    k: vec3<u32>,
    s: vec3<f32>,
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
    let a = abs(r.dir);
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
}

// `p * q - r * s` in f64 rounded to f32, as the CPU's fallback: both products are exact in f64,
// so contraction cannot change it.
fn det2_f64(p: f32, q: f32, r: f32, s: f32) -> f32 {
    return f32(f64(p) * f64(q) - f64(r) * f64(s));
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
    if u == 0.0 || v == 0.0 || w == 0.0 {
        u = det2_f64(cx, by, cy, bx);
        v = det2_f64(ax, cy, ay, cx);
        w = det2_f64(bx, ay, by, ax);
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
    if !is_finite(t) || t < tmin || t > tmax {
        return no;
    }
    return TriHit(true, t, div_rn(v, det), div_rn(w, det));
}
