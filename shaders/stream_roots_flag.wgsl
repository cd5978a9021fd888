// The traversal's first queue (`stream::traverse::traverse`): a pair (frustum, root) for every
// frustum with an active ray. This flags them; their exclusive scan places them
// (stream_roots_scatter.wgsl).
//
// S.n: frustums. Binding 8: the frustums; 9: the flags (out).

@group(0) @binding(8) var<storage, read_write> frustums: array<Frustum>;
@group(0) @binding(9) var<storage, read_write> flags: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let f = stream_item(gid);
    if f < S.n {
        flags[f] = select(0u, 1u, frustums[f].active_rays > 0u);
    }
}
