// Sets every value of an array to one value (the skeletons of decompression and packet
// decomposition, head flags cleared).
//
// S.n: values; S.a: the value. Binding 8: the array (out).

@group(0) @binding(8) var<storage, read_write> values: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = stream_item(gid);
    if i < S.n {
        values[i] = S.a;
    }
}
