// The numerics probe (backends/wgpu/src/probe.rs): per sample (a, b, c), the kernel writes
// div_rn(a, b), the native a / b, the native a * b + c (which the compiler may contract), and
// opq(a * b) + c (which it may not).

struct Params {
    zero: u32,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> samples: array<vec4<u32>>;
@group(0) @binding(2) var<storage, read_write> results: array<vec4<u32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= arrayLength(&samples) {
        return;
    }
    let s = bitcast<vec4<f32>>(samples[i]);
    results[i] = bitcast<vec4<u32>>(vec4<f32>(div_rn(s.x, s.y), s.x / s.y, s.x * s.y + s.z, opq(s.x * s.y) + s.z));
}
