// Localized intersection (`stream::localized::intersect_packet`): one invocation per sorted ray
// slot, against its packet's leaves in order, `S.v0.y` leaves at a time: the host dispatches
// round `S.v0.x` = 0, 1, ... until every packet's list is covered, and a round goes on from the
// hit the previous round stored (the paper's remedy for a frustum holding most leaves, Sec. 5.5,
// made sequential: one invocation's loop stays short; Mesa's lavapipe ends a shader's loops after
// about 32,768 iterations in all, and a 38,000-leaf list on the dragon lost its closest hit). A leaf whose box the ray does not enter over its
// current interval (up to its closest hit so far) is skipped (the paper's mask); the others are
// tested with wide.wgsl's leaf test. The hit goes to the ray's own index, so hits come back in the
// caller's order; so do the counters (a leaf entered, each triangle tested).
//
// S.n: rays; S.a: packets; S.v0: the round and the leaves per round. Binding 8: the sorted order; 9: packet bounds (S.a + 1); 10: each
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
    let p = packet_of(j);
    let first = ranges[2u * p];
    let count = ranges[2u * p + 1u];
    let round = S.v0.x;
    let per = S.v0.y;
    let start = round * per;
    if round > 0u && start >= count {
        return;
    }
    if round == 0u {
        rec_begin(id);
    } else {
        rec_select(id);
    }
    if !begin(rays[id]) {
        hits[id] = miss();
        return;
    }
    if round > 0u {
        Q_HIT = hits[id];
        if q_is_answered() {
            return;
        }
    }
    let end = min(count, start + per);
    for (var k = start; k < end; k = k + 1u) {
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
