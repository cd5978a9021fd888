// `out[i] = source[index[i]]`: the keys in sorted order, for packet decomposition.
//
// S.n: items. Binding 8: the indices; 9: the source; 10: out.

@group(0) @binding(8) var<storage, read_write> index: array<u32>;
@group(0) @binding(9) var<storage, read_write> source: array<u32>;
@group(0) @binding(10) var<storage, read_write> gathered: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = stream_item(gid);
    if i < S.n {
        gathered[i] = source[index[i]];
    }
}
