// The kernel: one invocation per ray. The method file defines `trace`.

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x + gid.y * P.row_width;
    if i >= P.ray_count {
        return;
    }
    rec_begin(i);
    hits[i] = trace(rays[i]);
}
