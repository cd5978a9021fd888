// Prelude of every raytrail kernel: the buffers, the per-batch parameters, the pipeline's
// override constants, and the per-invocation state shared by the method files.
//
// Composition order (backends/wgpu/src/compose.rs): generated constants, prelude, numerics,
// box, one triangle test, query, record, [keys + hash for stackless BVH2 methods], the method,
// entry.

// A ray as the host lays it out (32 bytes, `raytrail_core::Ray`).
struct Ray {
    origin: vec3<f32>,
    tmin: f32,
    dir: vec3<f32>,
    tmax: f32,
}

// A hit (16 bytes, `raytrail_core::Hit`); a miss has t = +inf and prim = NO_PRIM.
struct Hit {
    t: f32,
    prim: u32,
    u: f32,
    v: f32,
}

// Per-batch and per-scene constants (`Params` in backends/wgpu/src/params.rs).
struct Params {
    // Rays in this batch.
    ray_count: u32,
    // Invocations per dispatch row (the ray index is x + y * row_width).
    row_width: u32,
    // Root node reference (BVH2) or 0 (kd).
    root: u32,
    // Step budget: the loop ends after this many steps (never binds on intact tables).
    max_steps: u32,
    // Largest coordinate magnitude of the scene (for the per-ray slack).
    scene_scale: f32,
    // Always 0: an opaque zero the compiler cannot see through (see `opq`).
    zero: u32,
    // Perfect-hash displacement mask (size - 1) and table size.
    d_mask: u32,
    h: u32,
    // Offset of the leaf array in `bvh`, in 16-byte words.
    leaf_base: u32,
    // u32 slots per ray in `records`.
    record_stride: u32,
    // Node events kept per ray in `records` (enumerations).
    record_cap: u32,
    // kd: short-stack entries, offset of the references and of the triangles in `kd` (wide trees:
    // of the triangle entries, in words; their references are in the entries).
    short_stack: u32,
    kd_prims: u32,
    kd_tris: u32,
    // Wide BVH: the root leaf's triangle count (0: the root is node `root`).
    wide_root_count: u32,
    // Persistent threads: rounds a workgroup fetches at most (dispatch_persistent.wgsl).
    persistent_rounds: u32,
    // kd: scene box.
    kd_lo: vec4<f32>,
    kd_hi: vec4<f32>,
    // The stream kernel (wide_ray_stream.wgsl): this round of the batch (0: the streams start),
    // and the steps a stream takes in one round before it saves its state for the next.
    stream_round: u32,
    stream_steps: u32,
    // The all-hits kernel (all_hits.wgsl): hits a list keeps (the caller's limit and one more),
    // and whether hits at one t count once (nonzero).
    all_hits_keep: u32,
    all_hits_merge: u32,
    // Invocations per work item (0 and 1: one): a batch whose loops the device cut short is traced
    // again with one item per SIMD group (loop_guard.wgsl, `item_spread`).
    item_spread: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> rays: array<Ray>;
@group(0) @binding(2) var<storage, read_write> hits: array<Hit>;
// BVH2: internal nodes (four words each), then the leaf array from `P.leaf_base`; or a wide BVH
// (or the stream's level-order tree) read 16 bytes at a time, as wide.wgsl says.
@group(0) @binding(3) var<storage, read> bvh: array<vec4<u32>>;
// Perfect hash: the displacement table, then the cells from `P.d_mask + 1`.
@group(0) @binding(4) var<storage, read> hash_tables: array<u32>;
// kd-tree: nodes (two words each), references from `P.kd_prims`, triangles from `P.kd_tris`;
// or a wide BVH (the same buffer as `bvh`), read word by word.
@group(0) @binding(5) var<storage, read> kd: array<u32>;
// Per ray: event count, counters, then node events (see record.wgsl).
@group(0) @binding(6) var<storage, read_write> records: array<u32>;

// Closest hit (false) or any hit (true).
override ANY_HIT: bool = false;
// 0: hits only; 1: counters; 2: counters and node enumerations.
override RECORD: u32 = 0u;
// The disjoint t-interval mask of Binder & Keller 2016, Sec. 2.3 (methods stack-disjoint and
// hash-disjoint).
override DISJOINT: bool = false;

const NO_PRIM: u32 = 0xffffffffu;
// `NodeRef::NONE`: no node.
const NONE: u32 = 0x7fffffffu;

// What a step leaves to do (`traverse::Step`).
const STEP_CONTINUE: u32 = 0u;
const STEP_AFTER_HIT: u32 = 1u;
const STEP_DONE: u32 = 2u;

fn is_leaf(r: u32) -> bool {
    return r >= 0xc0000000u;
}

fn is_none(r: u32) -> bool {
    return r == NONE;
}

// The leaf reference of offset `o` and back (`NodeRef::leaf`, `NodeRef::offset`).
fn leaf_ref(o: u32) -> u32 {
    return ~o;
}

fn leaf_offset(r: u32) -> u32 {
    return ~r;
}

fn miss() -> Hit {
    return Hit(bitcast<f32>(0x7f800000u), NO_PRIM, 0.0, 0.0);
}
