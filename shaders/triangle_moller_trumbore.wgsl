// The Möller-Trumbore ray/triangle test (`intersect::MollerTrumbore`), fast and not watertight:
// glam's cross and dot products operation for operation, products fenced by `opq`.

struct TriRay {
    origin: vec3<f32>,
    dir: vec3<f32>,
}

var<private> TR: TriRay;

struct TriHit {
    ok: bool,
    t: f32,
    u: f32,
    v: f32,
}

fn tri_prepare(r: Ray) {
    TR.origin = r.origin;
    TR.dir = r.dir;
}

// `glam::Vec3::cross`: `(y * rz - ry * z, z * rx - rz * x, x * ry - rx * y)`.
fn cross_exact(p: vec3<f32>, r: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        opq(p.y * r.z) - opq(r.y * p.z),
        opq(p.z * r.x) - opq(r.z * p.x),
        opq(p.x * r.y) - opq(r.x * p.y),
    );
}

// `glam::Vec3::dot`: `(x * rx + y * ry) + z * rz`.
fn dot_exact(p: vec3<f32>, r: vec3<f32>) -> f32 {
    return opq(p.x * r.x) + opq(p.y * r.y) + opq(p.z * r.z);
}

fn tri_intersect(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, tmin: f32, tmax: f32) -> TriHit {
    let no = TriHit(false, 0.0, 0.0, 0.0);
    let e1 = b - a;
    let e2 = c - a;
    let p = cross_exact(TR.dir, e2);
    let det = dot_exact(e1, p);
    if det == 0.0 || !is_finite(det) {
        return no;
    }
    let inv = div_rn(1.0, det);
    let s = TR.origin - a;
    let u = opq(dot_exact(s, p) * inv);
    if !(u >= 0.0 && u <= 1.0) {
        return no;
    }
    let q = cross_exact(s, e1);
    let v = opq(dot_exact(TR.dir, q) * inv);
    if v < 0.0 || u + v > 1.0 {
        return no;
    }
    let t = dot_exact(e2, q) * inv;
    if !is_finite(t) || t < tmin || t > tmax {
        return no;
    }
    return TriHit(true, t, u, v);
}
