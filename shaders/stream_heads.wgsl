// Compression, first step (`stream::sort::compress`): a head flag where a key differs from the
// one before it. Their exclusive scan numbers the runs (stream_compact.wgsl).
//
// S.n: keys. Binding 8: the keys; 9: the flags (out).

@group(0) @binding(8) var<storage, read_write> keys: array<u32>;
@group(0) @binding(9) var<storage, read_write> heads: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = stream_item(gid);
    if i >= S.n {
        return;
    }
    heads[i] = select(0u, 1u, i == 0u || keys[i - 1u] != keys[i]);
}
