// Radix sort, last step of a pass: each chunk goes to its (digit, workgroup) position plus the
// number of chunks before it in its workgroup with the same digit, so the pass is stable.
//
// S.n: chunks; S.a: the digit's shift; S.b: workgroups. Bindings 8-10: keys, bases, sizes (in);
// 11: the scanned counts; 12-14: keys, bases, sizes (out).

@group(0) @binding(8) var<storage, read_write> keys_in: array<u32>;
@group(0) @binding(9) var<storage, read_write> bases_in: array<u32>;
@group(0) @binding(10) var<storage, read_write> sizes_in: array<u32>;
@group(0) @binding(11) var<storage, read_write> starts: array<u32>;
@group(0) @binding(12) var<storage, read_write> keys_out: array<u32>;
@group(0) @binding(13) var<storage, read_write> bases_out: array<u32>;
@group(0) @binding(14) var<storage, read_write> sizes_out: array<u32>;

var<workgroup> digits: array<u32, 256>;

@compute @workgroup_size(256)
fn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>,
    @builtin(local_invocation_index) l: u32) {
    let b = stream_block(wg, nw);
    let i = b * STREAM_GROUP + l;
    var key = 0u;
    // 256: no digit (past the end), equal to no real one.
    var digit = 256u;
    if i < S.n {
        key = keys_in[i];
        digit = (key >> S.a) & 0xffu;
    }
    digits[l] = digit;
    workgroupBarrier();
    if i < S.n {
        var rank = 0u;
        for (var j = 0u; j < l; j = j + 1u) {
            rank = rank + select(0u, 1u, digits[j] == digit);
        }
        let at = starts[digit * S.b + b] + rank;
        keys_out[at] = key;
        bases_out[at] = bases_in[i];
        sizes_out[at] = sizes_in[i];
    }
}
