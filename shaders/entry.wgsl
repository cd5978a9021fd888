// Work items of the one-ray-per-item kernels: item `i` is ray `i` of the batch. The method file
// defines `trace`; a dispatch file (`dispatch_grid` or `dispatch_persistent`) hands out the items.

fn item_count() -> u32 {
    return P.ray_count;
}

fn run_item(i: u32) {
    rec_begin(i);
    hits[i] = trace(rays[i]);
}
