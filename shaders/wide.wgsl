// The wide BVH (Guthe 2014) as every wide kernel reads it: its node layout, the children's box
// tests (`ChildKernel::test`), their visiting order (a bitonic sorting network for closest-hit
// queries, slot order for any-hit queries) and the leaf test. The traversals are wide_stack.wgsl
// (bvh4, bvh8, bvh4-naive, bvh8-sah), wide_packet.wgsl (bvh8-packet) and wide_trail.wgsl
// (bvh4-hash); the stream method's intersection kernel reads the leaf test.
//
// Memory: nodes of 8 * WIDE_W words each (`wide::WideNode`: lo x, y, z, hi x, y, z, children,
// counts; WIDE_W of each), then from word `P.kd_tris` each triangle in leaf order as three 16-byte
// entries (a and the primitive id, b, c: the BVH2 leaf's triangle entries). WIDE_W comes in the
// generated header. The buffer is bound twice: as `kd`, word by word, for the nodes, and as `bvh`,
// 16 bytes at a time, for the triangles. A triangle at a 36-byte stride took ten word loads that
// no compiler can merge; three aligned entries take three. The nodes stay word loads: read as
// 16-byte rows they ran 0-20% slower on an H100
// (`docs/notes/*-benchmarks-h100-suite.md`, "Tried on the H100 and not kept").

const WIDE_EMPTY: u32 = 0xffffffffu;

// A child: a node index (count 0), or a leaf's first triangle position and count.
struct WideChild {
    child: u32,
    count: u32,
}

// Where traversal starts (`WideRoot::root`): node `P.root`, or the leaf of a one-leaf tree.
fn wide_root() -> WideChild {
    if P.wide_root_count != 0u {
        return WideChild(leaf_offset(P.root), P.wide_root_count);
    }
    return WideChild(P.root, 0u);
}

// The reference an observer records (`WideChild::node_ref`).
fn wide_ref(c: WideChild) -> u32 {
    return select(c.child, leaf_ref(c.child), c.count != 0u);
}

fn wide_word(node: u32, at: u32) -> u32 {
    return kd[node * 8u * WIDE_W + at];
}

// Slot `i` of node `node` (`WideNode::child_ref`); `ok` false for an empty slot.
struct WideSlot {
    ok: bool,
    c: WideChild,
}

// Where slot `i`'s child lies in `kd` (its count lies WIDE_W words on): a 4-byte handle for the
// child that a stack entry can hold in place of child and count.
fn wide_child_word(node: u32, i: u32) -> u32 {
    return node * 8u * WIDE_W + 6u * WIDE_W + i;
}

// The child whose word is `word` (`wide_child_word`).
fn wide_child_at(word: u32) -> WideChild {
    return WideChild(kd[word], kd[word + WIDE_W]);
}

// Whether slot `i` holds a child, `child` being its child word's value.
fn wide_slot_ok(i: u32, child: u32) -> bool {
    return child != WIDE_EMPTY && i < WIDE_W;
}

fn wide_slot(node: u32, i: u32) -> WideSlot {
    let c = wide_child_at(wide_child_word(node, i));
    return WideSlot(wide_slot_ok(i, c.child), c);
}

// `ChildKernel::test`: each child box by the slab test over the widened interval. WT_T and WT_SLOT
// are the sort keys (`sort_keys`): by slot after the test, by rank after the network. Every index
// into them is a constant once the loops over WIDE_W are unrolled, which lets the compiler keep
// them in registers: a run-time index would send them to local memory, and on an H100 the kernels
// that indexed them by the hit count and the sorted slot ran at a quarter of the binary stack's
// speed.
var<private> WT_T: array<f32, WIDE_W>;
var<private> WT_SLOT: array<u32, WIDE_W>;

// Child `i`'s box test over `[lo_t, hi_t]` (`SlabRay::hit`).
fn wide_child_hit(node: u32, i: u32, lo_t: f32, hi_t: f32) -> BoxHit {
    let lo = vec3<f32>(bitcast<f32>(wide_word(node, i)), bitcast<f32>(wide_word(node, WIDE_W + i)),
        bitcast<f32>(wide_word(node, 2u * WIDE_W + i)));
    let hi = vec3<f32>(bitcast<f32>(wide_word(node, 3u * WIDE_W + i)),
        bitcast<f32>(wide_word(node, 4u * WIDE_W + i)), bitcast<f32>(wide_word(node, 5u * WIDE_W + i)));
    return slab_hit(lo, hi, lo_t, hi_t);
}

// Child `i`'s box test, its sort keys written at index `i` (a constant at every call).
fn wide_test_child(node: u32, i: u32, lo_t: f32, hi_t: f32) -> u32 {
    let h = wide_child_hit(node, i, lo_t, hi_t);
    // `sort_keys`: a missed child sorts after every hit one.
    WT_T[i] = select(bitcast<f32>(0x7f800000u), h.t_enter, h.hit);
    WT_SLOT[i] = select(i + WIDE_W, i, h.hit);
    return select(0u, 1u << i, h.hit);
}

// 4-wide: written out child by child, as `wide_sort` is, rather than left to the driver to unroll;
// on an H200 that made bvh4 1.00-1.18x faster (`docs/notes/*-benchmarks-h200.md`, "Loops written out").
// 8-wide: the loop, since written out there (with the stack's pushes) it lost 7-9% on AO and
// diffuse rays while gaining on primary ones.
fn wide_test(node: u32, lo_t: f32, hi_t: f32) -> u32 {
    if WIDE_W == 4u {
        return wide_test_child(node, 0u, lo_t, hi_t) | wide_test_child(node, 1u, lo_t, hi_t)
            | wide_test_child(node, 2u, lo_t, hi_t) | wide_test_child(node, 3u, lo_t, hi_t);
    }
    var mask = 0u;
    for (var i = 0u; i < WIDE_W; i = i + 1u) {
        mask = mask | wide_test_child(node, i, lo_t, hi_t);
    }
    return mask;
}

// `network::compare_and_swap`: the smaller (key, slot) to lane i, by conditional assignment.
fn wide_cas(i: u32, j: u32) {
    let ki = WT_T[i];
    let kj = WT_T[j];
    let si = WT_SLOT[i];
    let sj = WT_SLOT[j];
    let swap = kj < ki || (kj == ki && sj < si);
    WT_T[i] = select(ki, kj, swap);
    WT_T[j] = select(kj, ki, swap);
    WT_SLOT[i] = select(si, sj, swap);
    WT_SLOT[j] = select(sj, si, swap);
}

// `network::sort_network`: the bitonic network (Guthe's six compare-and-swaps for four keys),
// written out pair by pair so that every index is a constant. Any correct network leaves the same
// order, since the (key, slot) pairs are distinct.
fn wide_sort() {
    wide_cas(0u, 1u);
    wide_cas(2u, 3u);
    wide_cas(0u, 3u);
    wide_cas(1u, 2u);
    wide_cas(0u, 1u);
    wide_cas(2u, 3u);
    if WIDE_W == 8u {
        wide_cas(4u, 5u);
        wide_cas(6u, 7u);
        wide_cas(4u, 7u);
        wide_cas(5u, 6u);
        wide_cas(4u, 5u);
        wide_cas(6u, 7u);
        wide_cas(0u, 7u);
        wide_cas(1u, 6u);
        wide_cas(2u, 5u);
        wide_cas(3u, 4u);
        wide_cas(0u, 2u);
        wide_cas(1u, 3u);
        wide_cas(4u, 6u);
        wide_cas(5u, 7u);
        wide_cas(0u, 1u);
        wide_cas(2u, 3u);
        wide_cas(4u, 5u);
        wide_cas(6u, 7u);
    }
}

// The leaf's triangles; returns whether a hit was taken (an any-hit query stops at its first).
fn wide_leaf(first: u32, count: u32) -> bool {
    var taken = false;
    for (var pos = first; pos < first + count; pos = pos + 1u) {
        let e = P.kd_tris / 4u + pos * 3u;
        let a = bvh[e];
        rec_primitive();
        let h = tri_intersect(bitcast<vec3<f32>>(a.xyz), bitcast<vec3<f32>>(bvh[e + 1u].xyz),
            bitcast<vec3<f32>>(bvh[e + 2u].xyz), C.tmin, q_limit());
        if h.ok && q_offer(h, a.w) {
            taken = true;
            if ANY_HIT {
                return true;
            }
        }
    }
    return taken;
}

// The slot visited first among the hit children `mask` (nonzero): the nearest for a closest-hit
// query, after sorting WT_T and WT_SLOT by the network (which `wide_push` then reads); the
// smallest hit slot for an any-hit query.
fn wide_order(mask: u32) -> u32 {
    if ANY_HIT {
        return countTrailingZeros(mask);
    }
    wide_sort();
    return WT_SLOT[0] % WIDE_W;
}

// Push `k` of a node's expansion, k = WIDE_W - 1 down to 1 (`WideState::step`'s pushes): for a
// closest-hit query the child of rank k, pushed if hit (a miss sorts after every hit, so rank
// k < n is a hit); for an any-hit query slot k, pushed if hit and not the first. `n` hit
// children, `first_slot` visited next; WT_SLOT sorted by `wide_sort` for closest hits.
struct WidePush {
    push: bool,
    slot: u32,
}

fn wide_push(k: u32, mask: u32, first_slot: u32, n: u32) -> WidePush {
    if ANY_HIT {
        return WidePush((mask & (1u << k)) != 0u && k != first_slot, k);
    }
    return WidePush(k < n, WT_SLOT[k] % WIDE_W);
}
