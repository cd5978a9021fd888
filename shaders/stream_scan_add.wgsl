// The second half of a multi-level exclusive scan: each value gets the scanned total of the
// workgroups before its own (stream_scan.wgsl).
//
// S.n: values. Binding 8: the values (in place); 9: the workgroups' scanned totals.

@group(0) @binding(8) var<storage, read_write> values: array<u32>;
@group(0) @binding(9) var<storage, read_write> sums: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = stream_item(gid);
    if i >= S.n {
        return;
    }
    values[i] = values[i] + sums[i / STREAM_GROUP];
}
