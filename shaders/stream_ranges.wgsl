// The final queue compressed by frustum (`stream::traverse::traverse`, its last step): each run of
// one frustum's leaves gives that frustum its range, [first position, count]. Frustums with no
// leaves keep the [0, 0] the buffer was cleared to.
//
// S.n: runs. Bindings 8-10: the runs' frustums, bases and sizes; 11: two words per frustum (out).

@group(0) @binding(8) var<storage, read_write> run_keys: array<u32>;
@group(0) @binding(9) var<storage, read_write> run_bases: array<u32>;
@group(0) @binding(10) var<storage, read_write> run_sizes: array<u32>;
@group(0) @binding(11) var<storage, read_write> ranges: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let c = stream_item(gid);
    if c < S.n {
        let f = run_keys[c];
        ranges[2u * f] = run_bases[c];
        ranges[2u * f + 1u] = run_sizes[c];
    }
}
