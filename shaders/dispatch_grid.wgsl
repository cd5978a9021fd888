// One invocation per work item, over rows of `P.row_width` invocations (a large batch exceeds one
// dimension's workgroup limit), each checked by loop_guard.wgsl (bound before this file) when its
// item is done. The workgroup size is a pipeline override, so a sweep compiles variants rather than
// editing the source.

override WORKGROUP_SIZE: u32 = 64u;

@compute @workgroup_size(WORKGROUP_SIZE)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x + gid.y * P.row_width;
    let spread = item_spread();
    if i >= item_count() * spread || i % spread != 0u {
        return;
    }
    run_item(i / spread);
    guard_loops();
}
