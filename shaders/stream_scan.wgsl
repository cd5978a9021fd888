// One level of the exclusive prefix sum (`stream::scan::exclusive_scan`, wrapping like u32
// addition): each workgroup scans its STREAM_GROUP values in place (Hillis-Steele in workgroup
// memory) and writes its total to `sums`. Larger arrays scan `sums` the same way and add it back
// (stream_scan_add.wgsl); backends/wgpu/src/stream/scan.rs drives the levels.
//
// S.n: values. Binding 8: the values (in place); 9: one total per workgroup (out).

@group(0) @binding(8) var<storage, read_write> values: array<u32>;
@group(0) @binding(9) var<storage, read_write> sums: array<u32>;

var<workgroup> part: array<u32, 256>;

@compute @workgroup_size(256)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>,
    @builtin(local_invocation_index) l: u32) {
    let b = stream_block(wg, nw);
    let i = b * STREAM_GROUP + l;
    var v = 0u;
    if i < S.n {
        v = values[i];
    }
    part[l] = v;
    workgroupBarrier();
    for (var d = 1u; d < STREAM_GROUP; d = d * 2u) {
        var add = 0u;
        if l >= d {
            add = part[l - d];
        }
        workgroupBarrier();
        part[l] = part[l] + add;
        workgroupBarrier();
    }
    if i < S.n {
        // Inclusive minus the value itself: exclusive, exactly, in wrapping arithmetic.
        values[i] = part[l] - v;
    }
    if l == STREAM_GROUP - 1u && b * STREAM_GROUP < S.n {
        sums[b] = part[l];
    }
}
