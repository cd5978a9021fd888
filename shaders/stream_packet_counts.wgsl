// Packet decomposition (`stream::sort::packets`): how many packets of at most S.a rays a cell of
// equal keys is cut into, `size.div_ceil(S.a)`.
//
// S.n: cells; S.a: the packet size. Binding 8: the cells' sizes; 9: their packet counts (out).

@group(0) @binding(8) var<storage, read_write> sizes: array<u32>;
@group(0) @binding(9) var<storage, read_write> counts: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let c = stream_item(gid);
    if c < S.n {
        let s = sizes[c];
        counts[c] = s / S.a + select(0u, 1u, s % S.a != 0u);
    }
}
