// One level of the breadth-first traversal, second half: each pair writes its listed children,
// with its frustum, at its scanned offset in the next queue.
//
// S.n: pairs. Bindings 8, 9: the queue's frustums and nodes; 10: counts; 11: offsets (scanned);
// 12: eight children per pair; 13, 14: the next queue's frustums and nodes (out).

@group(0) @binding(8) var<storage, read_write> queue_frustum: array<u32>;
@group(0) @binding(9) var<storage, read_write> queue_node: array<u32>;
@group(0) @binding(10) var<storage, read_write> counts: array<u32>;
@group(0) @binding(11) var<storage, read_write> offsets: array<u32>;
@group(0) @binding(12) var<storage, read_write> children: array<u32>;
@group(0) @binding(13) var<storage, read_write> next_frustum: array<u32>;
@group(0) @binding(14) var<storage, read_write> next_node: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = stream_item(gid);
    if i >= S.n {
        return;
    }
    let f = queue_frustum[i];
    let at = offsets[i];
    for (var k = 0u; k < counts[i]; k = k + 1u) {
        next_frustum[at + k] = f;
        next_node[at + k] = children[i * 8u + k];
    }
}
