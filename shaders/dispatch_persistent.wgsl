// Persistent threads (Aila & Laine 2009): a fixed number of workgroups stays resident, and each
// fetches the next WORKGROUP_SIZE items from a global counter whenever all of its invocations are
// done, so a workgroup of long rays does not hold back a whole dispatch's tail. The batch is fetched
// per workgroup rather than per warp because WGSL has no portable warp: with WORKGROUP_SIZE 32 on
// NVIDIA the two are the same. The host zeroes `next_item` (loop_guard.wgsl's `DispatchState`, bound
// before this file) before every dispatch.
//
// A workgroup stops after `P.persistent_rounds` rounds even if items are left: the host launches
// enough workgroups that they cover the batch within that many rounds. Without the bound, a device
// that runs workgroups one after another (Mesa's lavapipe) lets the first take nearly every item,
// and lavapipe ends an invocation's loops after 65,535 iterations in all.

override WORKGROUP_SIZE: u32 = 64u;

var<workgroup> batch_start: u32;

@compute @workgroup_size(WORKGROUP_SIZE)
fn main(@builtin(local_invocation_index) lane: u32) {
    // Invocation slots: `item_spread` per item, of which the first takes it.
    let spread = item_spread();
    let n = item_count() * spread;
    for (var round = 0u; round < P.persistent_rounds; round = round + 1u) {
        if lane == 0u {
            batch_start = atomicAdd(&dispatch_state.next_item, WORKGROUP_SIZE);
        }
        // A barrier on either side of the load: every invocation sees this round's start, and
        // invocation 0 writes the next one only after all have read it.
        let start = workgroupUniformLoad(&batch_start);
        if start >= n {
            break;
        }
        let i = start + lane;
        if i < n && i % spread == 0u {
            run_item(i / spread);
        }
    }
    // After the fetch loop: a limiter that cut it short left items untraced.
    guard_loops();
}
