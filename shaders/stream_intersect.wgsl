// Localized intersection (`stream::localized::intersect_packet`): one invocation per sorted ray
// slot, against its packet's leaves in order. A leaf whose box the ray does not enter over its
// current interval (up to its closest hit so far) is skipped (the paper's mask); the others are
// tested with wide.wgsl's leaf test. The hit goes to the ray's own index, so hits come back in the
// caller's order; so do the counters (a leaf entered, each triangle tested).
//
// S.n: rays; S.a: packets. Binding 8: the sorted order; 9: packet bounds (S.a + 1); 10: each
// packet's range of leaves; 11: the final queue's nodes (the leaves).

@group(0) @binding(8) var<storage, read_write> order: array<u32>;
@group(0) @binding(9) var<storage, read_write> bounds: array<u32>;
@group(0) @binding(10) var<storage, read_write> ranges: array<u32>;
@group(0) @binding(11) var<storage, read_write> leaves: array<u32>;

// The packet holding sorted slot `j`: the last `p` with `bounds[p] <= j`.
fn packet_of(j: u32) -> u32 {
    var lo = 0u;
    var hi = S.a;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if bounds[mid] <= j {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let j = stream_item(gid);
    if j >= S.n {
        return;
    }
    let id = order[j];
    rec_begin(id);
    if !begin(rays[id]) {
        hits[id] = miss();
        return;
    }
    let p = packet_of(j);
    let first = ranges[2u * p];
    let count = ranges[2u * p + 1u];
    for (var k = 0u; k < count; k = k + 1u) {
        let n = level_node(leaves[first + k]);
        let iv = box_interval(q_limit());
        if !slab_hit(n.lo, n.hi, iv.x, iv.y).hit {
            continue;
        }
        rec_node(leaf_ref(n.first));
        wide_leaf(n.first, n.info >> 4u);
        if q_is_answered() {
            break;
        }
    }
    hits[id] = Q_HIT;
}
