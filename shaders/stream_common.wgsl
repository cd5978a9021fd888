// Shared by every kernel of the stream method (Garanzha & Loop 2010; `raytrail_core::stream`):
// the per-dispatch uniform, invocation indexing, Rust's and glam's min/max, and the frustum type.
//
// Stream kernels bind the prelude's buffers (0-6: `P`, rays, hits, the scene's `kd` buffer holding
// the level-order tree, records), then `S` at 7 and their own arrays at 8 and up (each kernel file
// names them). Every kernel runs in workgroups of STREAM_GROUP invocations, dispatched as a grid
// of rows of `S.row_width` invocations (a large array exceeds one dimension's workgroup limit).

const STREAM_GROUP: u32 = 256u;

// Per-dispatch values (`StageUniform` in backends/wgpu/src/stream/run.rs).
struct Stage {
    // Items (invocations that do work).
    n: u32,
    // Invocations per row of the dispatch grid.
    row_width: u32,
    // Kernel-specific scalars and vectors (each kernel file says what they hold).
    a: u32,
    b: u32,
    v0: vec4<u32>,
    v1: vec4<u32>,
    v2: vec4<u32>,
}

@group(0) @binding(7) var<uniform> S: Stage;

// The item of this invocation (may be `>= S.n` in the last row).
fn stream_item(gid: vec3<u32>) -> u32 {
    return gid.x + gid.y * S.row_width;
}

// The linear index of this workgroup.
fn stream_block(wg: vec3<u32>, nw: vec3<u32>) -> u32 {
    return wg.x + wg.y * nw.x;
}

// Rust's `f32::min`: a NaN operand gives the other one. (Ties of -0 and +0 are left to the
// platform there; the stream kernels only take these where a margin is added afterwards or the
// result is only compared, so either zero gives the same bits or the same decision.)
fn rust_min(a: f32, b: f32) -> f32 {
    return select(a, b, b < a || is_nan(a));
}

fn rust_max(a: f32, b: f32) -> f32 {
    return select(a, b, b > a || is_nan(a));
}

// glam's `Vec3::min` / `Vec3::max`: `if a < b { a } else { b }` per component.
fn glam_min(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return select(b, a, a < b);
}

fn glam_max(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return select(b, a, a > b);
}

// A packet's frustum (`stream::Frustum`, 80 bytes).
struct Frustum {
    lo: vec3<f32>,
    axis: u32,
    hi: vec3<f32>,
    active_rays: u32,
    near: f32,
    far: f32,
    inv_span: f32,
    dir_signs: u32,
    near_rect: vec4<f32>,
    far_rect: vec4<f32>,
}
