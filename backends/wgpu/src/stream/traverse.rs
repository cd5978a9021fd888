//! The breadth-first frustum traversal on the device (`raytrail_core::stream::traverse`): a
//! queue of (frustum, node) pairs expanded a level at a time by an expand kernel, an exclusive
//! scan of the counts and a scatter kernel. The host reads each level's total back to size the
//! next queue, and stops as the core does, when no internal node is left in the queue.

use super::compose::StreamKernel;
use super::run::{Run, StageUniform};
use super::scan::{exclusive_scan, read_total};
use super::sort::compress;
use raytrail_core::Error;

/// What the traversal leaves on the device, and its figures.
pub(crate) struct GpuLeafLists {
    /// The final queue's frustums and nodes (leaves), grouped by frustum in frustum order.
    pub frustum: wgpu::Buffer,
    pub node: wgpu::Buffer,
    pub len: u32,
    /// Two words per frustum: its first position in the final queue and its leaf count.
    pub ranges: wgpu::Buffer,
    /// Frustums with an active ray (the first queue's length).
    pub active: u32,
    /// Queue length at the start of each level, then the final queue's.
    pub queue_sizes: Vec<u32>,
    /// Frustum-box tests.
    pub box_tests: u64,
    /// The longest queue.
    pub biggest: u32,
}

/// Traverses the tree (whose root is a leaf when `root_is_leaf`) with the `count` frustums.
pub(crate) fn traverse(
    run: &mut Run<'_>,
    frustums: &wgpu::Buffer,
    count: u32,
    root_is_leaf: bool,
) -> Result<GpuLeafLists, Error> {
    // The first queue: (f, root) for every frustum with an active ray.
    let slots = run.array("root slots", u64::from(count))?;
    run.dispatch(StreamKernel::RootsFlag, count, StageUniform::items(count), &[frustums, &slots])?;
    let total = exclusive_scan(run, &slots, count)?;
    let active = read_total(run, &total)?;
    let mut qf = run.array("queue frustums", u64::from(active))?;
    let mut qn = run.array("queue nodes", u64::from(active))?;
    run.dispatch(StreamKernel::RootsScatter, count, StageUniform::items(count), &[frustums, &slots, &qf, &qn])?;
    let mut len = active;
    let mut internal = len > 0 && !root_is_leaf;
    let (mut queue_sizes, mut box_tests) = (Vec::new(), 0u64);
    while internal {
        queue_sizes.push(len);
        let counts = run.array("child counts", u64::from(len))?;
        let offsets = run.array("child offsets", u64::from(len))?;
        let children = run.array("children", 8 * u64::from(len))?;
        let stats = run.array("level figures", 3)?;
        let arrays = [frustums, &qf, &qn, &counts, &offsets, &children, &stats];
        run.dispatch(StreamKernel::Expand, len, StageUniform::items(len), &arrays)?;
        let total = exclusive_scan(run, &offsets, len)?;
        let (next, figures) = match &total {
            Some((buffer, at)) => {
                let back = run.read(&[(buffer, *at, 1), (&stats, 0, 3)])?;
                (back[0][0], back[1].clone())
            }
            None => (0, vec![0; 3]),
        };
        box_tests += u64::from(figures[0]) | (u64::from(figures[1]) << 32);
        internal = figures[2] > 0;
        let nf = run.array("queue frustums", u64::from(next))?;
        let nn = run.array("queue nodes", u64::from(next))?;
        let arrays = [&qf, &qn, &counts, &offsets, &children, &nf, &nn];
        run.dispatch(StreamKernel::PairScatter, len, StageUniform::items(len), &arrays)?;
        (qf, qn, len) = (nf, nn, next);
    }
    queue_sizes.push(len);
    // The final queue compressed by frustum id into ranges.
    let runs = compress(run, &qf, len)?;
    let ranges = run.array("leaf ranges", 2 * u64::from(count))?;
    run.dispatch(
        StreamKernel::Ranges,
        runs.len,
        StageUniform::items(runs.len),
        &[&runs.key, &runs.base, &runs.size, &ranges],
    )?;
    let biggest = queue_sizes.iter().copied().max().unwrap_or(0);
    Ok(GpuLeafLists { frustum: qf, node: qn, len, ranges, active, queue_sizes, box_tests, biggest })
}
