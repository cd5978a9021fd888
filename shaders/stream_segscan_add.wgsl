// The second half of a multi-level segmented scan: a value with no head at or before it in its
// workgroup continues the segment running out of the workgroups before, whose inclusive
// segmented sum is `carry_values[workgroup - 1]` (stream_segscan.wgsl).
//
// S.n: values. Binding 8: values (in place); 9: in-workgroup flags; 10: the scanned carries.

@group(0) @binding(8) var<storage, read_write> values: array<u32>;
@group(0) @binding(9) var<storage, read_write> flags: array<u32>;
@group(0) @binding(10) var<storage, read_write> carry_values: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = stream_item(gid);
    let b = i / STREAM_GROUP;
    if i >= S.n || b == 0u || flags[i] != 0u {
        return;
    }
    values[i] = values[i] + carry_values[b - 1u];
}
