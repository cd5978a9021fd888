// The level-order 8-wide tree (`stream::LevelNode`, eight words a node) as the stream kernels read
// it from the `kd` binding: nodes from word 0, then primitive ids from `P.kd_prims` and triangles
// from `P.kd_tris`, the wide trees' layout, so wide.wgsl's leaf test reads the triangles.

struct LevelNode {
    lo: vec3<f32>,
    // First child (internal node) or first triangle position (leaf).
    first: u32,
    hi: vec3<f32>,
    // Bits 0-3: children (0 for a leaf); internal: child k's octant at bit 8 + 3k; leaf: the
    // triangle count from bit 4.
    info: u32,
}

fn level_node(i: u32) -> LevelNode {
    let b = i * 8u;
    let lo = bitcast<vec3<f32>>(vec3<u32>(kd[b], kd[b + 1u], kd[b + 2u]));
    let hi = bitcast<vec3<f32>>(vec3<u32>(kd[b + 4u], kd[b + 5u], kd[b + 6u]));
    return LevelNode(lo, kd[b + 3u], hi, kd[b + 7u]);
}

fn level_children(n: LevelNode) -> u32 {
    return n.info & 0xfu;
}

fn level_octant(n: LevelNode, k: u32) -> u32 {
    return (n.info >> (8u + 3u * k)) & 7u;
}
