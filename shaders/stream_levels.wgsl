// The level-order 8-wide tree (`stream::LevelNode`, eight words a node) as the stream kernels read
// it: nodes from word 0, then the triangle entries from `P.kd_tris`, the wide trees' layout (bound
// as `kd` and as `bvh`), so wide.wgsl's leaf test reads the triangles.

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
    let a = bvh[2u * i];
    let b = bvh[2u * i + 1u];
    return LevelNode(bitcast<vec3<f32>>(a.xyz), a.w, bitcast<vec3<f32>>(b.xyz), b.w);
}

fn level_children(n: LevelNode) -> u32 {
    return n.info & 0xfu;
}

fn level_octant(n: LevelNode, k: u32) -> u32 {
    return (n.info >> (8u + 3u * k)) & 7u;
}
