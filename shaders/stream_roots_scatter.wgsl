// Writes the first queue's pairs (frustum, node 0) at the scanned flags' positions.
//
// S.n: frustums. Binding 8: the frustums; 9: the positions; 10, 11: the queue's frustums and
// nodes (out).

@group(0) @binding(8) var<storage, read_write> frustums: array<Frustum>;
@group(0) @binding(9) var<storage, read_write> slots: array<u32>;
@group(0) @binding(10) var<storage, read_write> queue_frustum: array<u32>;
@group(0) @binding(11) var<storage, read_write> queue_node: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let f = stream_item(gid);
    if f < S.n && frustums[f].active_rays > 0u {
        queue_frustum[slots[f]] = f;
        queue_node[slots[f]] = 0u;
    }
}
