// The skeleton of a segmented expansion (`stream::sort::{decompress, packets}`): run `c` puts its
// base at its first output position and flags a segment head there. The skeleton was filled with
// the step (1 for decompression, the packet size for packets); its inclusive segmented scan then
// counts up from each base.
//
// S.n: runs; S.a: the skeleton's length. Binding 8: the runs' first output positions; 9: their
// bases; 10: the skeleton; 11: the head flags.

@group(0) @binding(8) var<storage, read_write> firsts: array<u32>;
@group(0) @binding(9) var<storage, read_write> bases: array<u32>;
@group(0) @binding(10) var<storage, read_write> skeleton: array<u32>;
@group(0) @binding(11) var<storage, read_write> heads: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let c = stream_item(gid);
    if c >= S.n {
        return;
    }
    let at = firsts[c];
    if at < S.a {
        skeleton[at] = bases[c];
        heads[at] = 1u;
    }
}
