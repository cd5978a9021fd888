// One level of the breadth-first traversal (`stream::traverse::expand_pair`): one invocation per
// (frustum, node) pair. A leaf is its own single child; an internal node's children that the
// frustum overlaps are listed nearest side first (octant XOR the frustum's direction signs, ties
// by slot). Counts go to `counts` and `offsets` (the latter is scanned in place to place them).
// `stats` accumulates the level's frustum-box tests (a 64-bit count as two words) and how many
// of the listed children are internal nodes (the host stops when none is).
//
// S.n: pairs. Binding 8: frustums; 9, 10: the queue's frustums and nodes; 11, 12: counts (out,
// twice); 13: eight children per pair (out); 14: stats (box tests low, high, internal children).

@group(0) @binding(8) var<storage, read_write> frustums: array<Frustum>;
@group(0) @binding(9) var<storage, read_write> queue_frustum: array<u32>;
@group(0) @binding(10) var<storage, read_write> queue_node: array<u32>;
@group(0) @binding(11) var<storage, read_write> counts: array<u32>;
@group(0) @binding(12) var<storage, read_write> offsets: array<u32>;
@group(0) @binding(13) var<storage, read_write> children: array<u32>;
@group(0) @binding(14) var<storage, read_write> stats: array<atomic<u32>>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = stream_item(gid);
    if i >= S.n {
        return;
    }
    let node = queue_node[i];
    let n = level_node(node);
    let child_count = level_children(n);
    if child_count == 0u {
        children[i * 8u] = node;
        counts[i] = 1u;
        offsets[i] = 1u;
        return;
    }
    let f = frustums[queue_frustum[i]];
    // Key: the visiting rank in the high bits, the slot in the low four.
    var keys: array<u32, 8>;
    var count = 0u;
    for (var k = 0u; k < child_count; k = k + 1u) {
        let c = level_node(n.first + k);
        if frustum_overlaps(f, c.lo, c.hi) {
            keys[count] = ((level_octant(n, k) ^ f.dir_signs) << 4u) | k;
            count = count + 1u;
        }
    }
    // Insertion sort: keys are distinct (the slot is in them), so any sort gives this order.
    for (var j = 1u; j < count; j = j + 1u) {
        let key = keys[j];
        var at = j;
        while at > 0u && keys[at - 1u] > key {
            keys[at] = keys[at - 1u];
            at = at - 1u;
        }
        keys[at] = key;
    }
    var internal = 0u;
    for (var j = 0u; j < count; j = j + 1u) {
        let child = n.first + (keys[j] & 0xfu);
        children[i * 8u + j] = child;
        if level_children(level_node(child)) != 0u {
            internal = internal + 1u;
        }
    }
    counts[i] = count;
    offsets[i] = count;
    let before = atomicAdd(&stats[0], child_count);
    if before + child_count < before {
        atomicAdd(&stats[1], 1u);
    }
    if internal != 0u {
        atomicAdd(&stats[2], internal);
    }
}
