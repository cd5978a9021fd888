// One level of the inclusive segmented prefix sum (`stream::scan::segmented_inclusive_scan`): the
// running sum restarts at every set head flag. Each workgroup scans its values as (flag, value)
// pairs, whose combination `(f1, v1) + (f2, v2) = (f1 | f2, f2 ? v2 : v1 + v2)` is associative,
// and leaves in `flags` whether a head lies at or before each position within the workgroup. The
// workgroups' last pairs are scanned the same way and carried in (stream_segscan_add.wgsl).
//
// S.n: values. Binding 8: values (in place); 9: head flags (in), in-workgroup flags (out);
// 10, 11: each workgroup's last value and flag (out).

@group(0) @binding(8) var<storage, read_write> values: array<u32>;
@group(0) @binding(9) var<storage, read_write> flags: array<u32>;
@group(0) @binding(10) var<storage, read_write> carry_values: array<u32>;
@group(0) @binding(11) var<storage, read_write> carry_flags: array<u32>;

var<workgroup> part_v: array<u32, 256>;
var<workgroup> part_f: array<u32, 256>;

@compute @workgroup_size(256)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>,
    @builtin(local_invocation_index) l: u32) {
    let b = stream_block(wg, nw);
    let i = b * STREAM_GROUP + l;
    var v = 0u;
    var f = 0u;
    if i < S.n {
        v = values[i];
        f = select(0u, 1u, flags[i] != 0u);
    }
    part_v[l] = v;
    part_f[l] = f;
    workgroupBarrier();
    for (var d = 1u; d < STREAM_GROUP; d = d * 2u) {
        var before_v = 0u;
        var before_f = 0u;
        if l >= d {
            before_v = part_v[l - d];
            before_f = part_f[l - d];
        }
        workgroupBarrier();
        if l >= d {
            if part_f[l] == 0u {
                part_v[l] = before_v + part_v[l];
            }
            part_f[l] = part_f[l] | before_f;
        }
        workgroupBarrier();
    }
    if i < S.n {
        values[i] = part_v[l];
        flags[i] = part_f[l];
    }
    if l == STREAM_GROUP - 1u && b * STREAM_GROUP < S.n {
        carry_values[b] = part_v[l];
        carry_flags[b] = part_f[l];
    }
}
