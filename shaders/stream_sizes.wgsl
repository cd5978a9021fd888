// Compression, last step: a run's length is the next run's base minus its own (the array's
// length after the last run).
//
// S.n: runs; S.a: the compressed array's length. Binding 8: bases; 9: sizes (out).

@group(0) @binding(8) var<storage, read_write> bases: array<u32>;
@group(0) @binding(9) var<storage, read_write> sizes: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let c = stream_item(gid);
    if c >= S.n {
        return;
    }
    var end = S.a;
    if c + 1u < S.n {
        end = bases[c + 1u];
    }
    sizes[c] = end - bases[c];
}
