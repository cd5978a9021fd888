//! The scans the stream method is built from, on the device, for arrays of any length: one
//! workgroup-level pass, then (past one workgroup) the workgroups' totals scanned the same way and
//! added back (shaders/stream_scan*.wgsl, stream_segscan*.wgsl).

use super::compose::StreamKernel;
use super::run::{Run, StageUniform, GROUP};
use raytrail_core::Error;

/// Where a scan left its total: a word of a buffer (none for an empty array, whose total is 0).
pub(crate) type Total = Option<(wgpu::Buffer, u32)>;

/// The exclusive prefix sum of the first `n` words of `values`, in place (wrapping).
pub(crate) fn exclusive_scan(run: &mut Run<'_>, values: &wgpu::Buffer, n: u32) -> Result<Total, Error> {
    if n == 0 {
        return Ok(None);
    }
    let blocks = n.div_ceil(GROUP);
    let sums = run.array("scan totals", u64::from(blocks))?;
    run.dispatch(StreamKernel::Scan, blocks * GROUP, StageUniform::items(n), &[values, &sums])?;
    if blocks == 1 {
        return Ok(Some((sums, 0)));
    }
    let total = exclusive_scan(run, &sums, blocks)?;
    run.dispatch(StreamKernel::ScanAdd, n, StageUniform::items(n), &[values, &sums])?;
    Ok(total)
}

/// The total of a scan, read back (a submission).
pub(crate) fn read_total(run: &mut Run<'_>, total: &Total) -> Result<u32, Error> {
    match total {
        Some((buffer, at)) => run.read_word(buffer, *at),
        None => Ok(0),
    }
}

/// The inclusive segmented prefix sum of the first `n` words of `values`, in place, segments
/// starting at the nonzero words of `heads` (which it overwrites).
pub(crate) fn segmented_scan(
    run: &mut Run<'_>,
    values: &wgpu::Buffer,
    heads: &wgpu::Buffer,
    n: u32,
) -> Result<(), Error> {
    if n == 0 {
        return Ok(());
    }
    let blocks = n.div_ceil(GROUP);
    let carry_values = run.array("segmented scan carries", u64::from(blocks))?;
    let carry_flags = run.array("segmented scan carry flags", u64::from(blocks))?;
    let arrays = [values, heads, &carry_values, &carry_flags];
    run.dispatch(StreamKernel::SegScan, blocks * GROUP, StageUniform::items(n), &arrays)?;
    if blocks > 1 {
        segmented_scan(run, &carry_values, &carry_flags, blocks)?;
        run.dispatch(StreamKernel::SegScanAdd, n, StageUniform::items(n), &[values, heads, &carry_values])?;
    }
    Ok(())
}
