// A BVH2 leaf: a run of triangles, three 16-byte entries each, closed by a terminator entry
// carrying three links (`traverse::intersect_leaf`, `bvh2::LeafWord`).

const TERMINATOR: u32 = 0xffffffffu;

fn leaf_word(o: u32) -> vec4<u32> {
    return bvh[P.leaf_base + o];
}

// The leaf's three links and whether it accepted a hit.
struct LeafResult {
    links: vec3<u32>,
    hit: bool,
}

fn intersect_leaf(offset: u32) -> LeafResult {
    var o = offset;
    var accepted = false;
    loop {
        let w0 = leaf_word(o);
        if w0.w == TERMINATOR {
            return LeafResult(w0.xyz, accepted);
        }
        let prim = w0.w;
        rec_primitive();
        let w1 = leaf_word(o + 1u);
        let w2 = leaf_word(o + 2u);
        let h = tri_intersect(bitcast<vec3<f32>>(w0.xyz), bitcast<vec3<f32>>(w1.xyz), bitcast<vec3<f32>>(w2.xyz),
            C.tmin, q_limit());
        if h.ok && q_offer(h, prim) {
            accepted = true;
            if ANY_HIT {
                return LeafResult(vec3<u32>(NONE), true);
            }
        }
        o = o + 3u;
    }
    // Unreachable: the loop returns at the terminator.
    return LeafResult(vec3<u32>(NONE), accepted);
}

// The first two links of a node without searching a leaf's terminator
// (`BvhMemory::hop_links`).
fn hop_links(r: u32) -> vec2<u32> {
    if is_leaf(r) {
        let o = leaf_offset(r);
        return vec2<u32>(leaf_word(o + 1u).w, leaf_word(o + 2u).w);
    }
    return bvh[r * 4u + 3u].zw;
}
