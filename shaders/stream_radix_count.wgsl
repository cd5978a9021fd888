// Radix sort, first step of a pass (`stream::sort::radix_sort`): each workgroup counts the
// 8-bit digits of its STREAM_GROUP keys. Counts are stored digit-major, so one exclusive scan of
// them gives every (digit, workgroup) its first output position, in the stable order.
//
// S.n: keys; S.a: the digit's shift; S.b: workgroups. Binding 8: keys; 9: counts (out, 256 * S.b).

@group(0) @binding(8) var<storage, read_write> keys: array<u32>;
@group(0) @binding(9) var<storage, read_write> counts: array<u32>;

var<workgroup> histogram: array<atomic<u32>, 256>;

@compute @workgroup_size(256)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>,
    @builtin(local_invocation_index) l: u32) {
    let b = stream_block(wg, nw);
    atomicStore(&histogram[l], 0u);
    workgroupBarrier();
    let i = b * STREAM_GROUP + l;
    if i < S.n {
        atomicAdd(&histogram[(keys[i] >> S.a) & 0xffu], 1u);
    }
    workgroupBarrier();
    let count = atomicLoad(&histogram[l]);
    if b < S.b {
        counts[l * S.b + b] = count;
    }
}
