//! Ray sorting on the device (`raytrail_core::stream::sort`): compression of equal keys into
//! chunks, a stable radix sort of the chunks, decompression into the rays' sorted order, and the
//! decomposition of the sorted rays into packets.

use super::compose::StreamKernel;
use super::run::{Run, StageUniform, GROUP};
use super::scan::{exclusive_scan, read_total, segmented_scan};
use raytrail_core::Error;

/// Runs of equal keys on the device: key, first position and length of each.
pub(crate) struct Chunks {
    pub key: wgpu::Buffer,
    pub base: wgpu::Buffer,
    pub size: wgpu::Buffer,
    pub len: u32,
}

/// Compresses the first `n` words of `keys` into runs (`sort::compress`): head flags, their
/// exclusive scan as the runs' slots (the run count read back), the heads' keys and positions
/// written there, lengths from consecutive positions.
pub(crate) fn compress(run: &mut Run<'_>, keys: &wgpu::Buffer, n: u32) -> Result<Chunks, Error> {
    let slots = run.array("run slots", u64::from(n))?;
    run.dispatch(StreamKernel::Heads, n, StageUniform::items(n), &[keys, &slots])?;
    let total = exclusive_scan(run, &slots, n)?;
    let len = read_total(run, &total)?;
    let key = run.array("run keys", u64::from(len))?;
    let base = run.array("run bases", u64::from(len))?;
    let size = run.array("run sizes", u64::from(len))?;
    run.dispatch(StreamKernel::Compact, n, StageUniform::items(n), &[keys, &slots, &key, &base])?;
    run.dispatch(StreamKernel::Sizes, len, StageUniform::items(len).a(n), &[&base, &size])?;
    Ok(Chunks { key, base, size, len })
}

/// Sorts the chunks by key, stably (`sort::radix_sort`): four passes of eight bits, each a
/// per-workgroup digit count, one exclusive scan of the counts, a stable scatter.
pub(crate) fn radix_sort(run: &mut Run<'_>, chunks: Chunks) -> Result<Chunks, Error> {
    let m = chunks.len;
    if m == 0 {
        return Ok(chunks);
    }
    let blocks = m.div_ceil(GROUP);
    let counts = run.array("digit counts", 256 * u64::from(blocks))?;
    let mut from = chunks;
    let mut to = Chunks {
        key: run.array("sorted keys", u64::from(m))?,
        base: run.array("sorted bases", u64::from(m))?,
        size: run.array("sorted sizes", u64::from(m))?,
        len: m,
    };
    for pass in 0..4 {
        let stage = StageUniform::items(m).a(8 * pass).b(blocks);
        run.dispatch(StreamKernel::RadixCount, blocks * GROUP, stage, &[&from.key, &counts])?;
        exclusive_scan(run, &counts, 256 * blocks)?;
        let arrays = [&from.key, &from.base, &from.size, &counts, &to.key, &to.base, &to.size];
        run.dispatch(StreamKernel::RadixScatter, blocks * GROUP, stage, &arrays)?;
        std::mem::swap(&mut from, &mut to);
    }
    Ok(from)
}

/// The sorted order of the `n` rays (`sort::decompress`): the chunks' first sorted positions by
/// an exclusive scan of their sizes, a skeleton of ones holding each chunk's base there, and its
/// inclusive segmented scan.
pub(crate) fn decompress(run: &mut Run<'_>, chunks: &Chunks, n: u32) -> Result<wgpu::Buffer, Error> {
    let starts = run.array("chunk starts", u64::from(chunks.len))?;
    run.copy(&chunks.size, &starts, chunks.len);
    exclusive_scan(run, &starts, chunks.len)?;
    let order = run.array("sorted order", u64::from(n))?;
    let heads = run.array("order heads", u64::from(n))?;
    run.dispatch(StreamKernel::Fill, n, StageUniform::items(n).a(1), &[&order])?;
    run.dispatch(StreamKernel::Fill, n, StageUniform::items(n), &[&heads])?;
    let skeleton = StageUniform::items(chunks.len).a(n);
    run.dispatch(StreamKernel::Skeleton, chunks.len, skeleton, &[&starts, &chunks.base, &order, &heads])?;
    segmented_scan(run, &order, &heads, n)?;
    Ok(order)
}

/// Packet bounds (`sort::packets`): the sorted keys compressed into cells, each cell cut into
/// packets of at most `max` rays (a scan of the per-cell packet counts, a skeleton of `max` headed
/// by each cell's base, its segmented scan), then `n` after the last. Returns the bounds and the
/// packet count.
pub(crate) fn packets(
    run: &mut Run<'_>,
    keys: &wgpu::Buffer,
    order: &wgpu::Buffer,
    n: u32,
    max: u32,
) -> Result<(wgpu::Buffer, u32), Error> {
    let max = max.max(1);
    let sorted = run.array("sorted keys", u64::from(n))?;
    run.dispatch(StreamKernel::Gather, n, StageUniform::items(n), &[order, keys, &sorted])?;
    let cells = compress(run, &sorted, n)?;
    let firsts = run.array("packets per cell", u64::from(cells.len))?;
    run.dispatch(
        StreamKernel::PacketCounts,
        cells.len,
        StageUniform::items(cells.len).a(max),
        &[&cells.size, &firsts],
    )?;
    let total = exclusive_scan(run, &firsts, cells.len)?;
    let count = read_total(run, &total)?;
    let bounds = run.array("packet bounds", u64::from(count) + 1)?;
    let heads = run.array("packet heads", u64::from(count))?;
    run.dispatch(StreamKernel::Fill, count, StageUniform::items(count).a(max), &[&bounds])?;
    let skeleton = StageUniform::items(cells.len).a(count);
    run.dispatch(StreamKernel::Skeleton, cells.len, skeleton, &[&firsts, &cells.base, &bounds, &heads])?;
    segmented_scan(run, &bounds, &heads, count)?;
    run.write_word(&bounds, count, n);
    Ok((bounds, count))
}
