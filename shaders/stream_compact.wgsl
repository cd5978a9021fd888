// Compression, second step: each run's head writes its key and first position into the run's
// slot (the exclusive scan of the head flags). The head test is made again rather than kept,
// since the scan overwrote the flags.
//
// S.n: keys. Binding 8: the keys; 9: the slots; 10, 11: the runs' keys and bases (out).

@group(0) @binding(8) var<storage, read_write> keys: array<u32>;
@group(0) @binding(9) var<storage, read_write> slots: array<u32>;
@group(0) @binding(10) var<storage, read_write> run_keys: array<u32>;
@group(0) @binding(11) var<storage, read_write> run_bases: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = stream_item(gid);
    if i >= S.n || !(i == 0u || keys[i - 1u] != keys[i]) {
        return;
    }
    run_keys[slots[i]] = keys[i];
    run_bases[slots[i]] = i;
}
