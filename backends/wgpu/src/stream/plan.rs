//! Stages one to three on the device (`raytrail_core::stream::pipeline::plan`), and their arrays
//! read back as the core's [`StreamPlan`].

use super::compose::StreamKernel;
use super::run::{Run, StageUniform};
use super::sort::{compress, decompress, packets, radix_sort};
use super::traverse::{traverse, GpuLeafLists};
use raytrail_core::glam::Vec3;
use raytrail_core::stream::pipeline::StreamPlan;
use raytrail_core::stream::ray_hash::RayGrid;
use raytrail_core::stream::traverse::{LeafLists, PairQueue};
use raytrail_core::stream::{Frustum, StreamParams, StreamScene};
use raytrail_core::{Error, Ray};

/// Words of a frustum (`Frustum` is 80 bytes).
const FRUSTUM_WORDS: u32 = 20;

/// The plan's arrays on the device.
pub(crate) struct GpuPlan {
    pub keys: wgpu::Buffer,
    pub order: wgpu::Buffer,
    /// Packet bounds (`packets + 1` words).
    pub bounds: wgpu::Buffer,
    pub packets: u32,
    pub frustums: wgpu::Buffer,
    pub lists: GpuLeafLists,
}

fn bits3(v: [f32; 3]) -> [u32; 3] {
    v.map(f32::to_bits)
}

/// Keys, sort, packets (stage 0), frustums (stage 1), traversal (stage 2) of `n` rays.
pub(crate) fn plan(
    run: &mut Run<'_>,
    scene: &StreamScene<'_>,
    n: u32,
    params: &StreamParams,
) -> Result<GpuPlan, Error> {
    params.check()?;
    let grid = RayGrid::new(&scene.bounds, params);
    let keys = run.array("ray keys", u64::from(n))?;
    let [lx, ly, lz] = bits3(grid.lo.to_array());
    let mut stage = StageUniform::items(n);
    stage.v = [
        [lx, ly, lz, grid.inv_cell.to_bits()],
        [grid.cells[0], grid.cells[1], grid.cells[2], grid.origin_bits],
        [grid.dir_cells, grid.face_bits, grid.origin_drop, 0],
    ];
    run.dispatch(StreamKernel::Keys, n, stage, &[&keys])?;
    let chunks = compress(run, &keys, n)?;
    let chunks = radix_sort(run, chunks)?;
    let order = decompress(run, &chunks, n)?;
    let (bounds, count) = packets(run, &keys, &order, n, params.max_packet)?;
    run.next_stage(1)?;
    let frustums = run.array("frustums", u64::from(FRUSTUM_WORDS) * u64::from(count))?;
    let mut stage = StageUniform::items(count);
    let ([x0, y0, z0], [x1, y1, z1]) = (bits3(scene.bounds.min.to_array()), bits3(scene.bounds.max.to_array()));
    stage.v[0] = [x0, y0, z0, 0];
    stage.v[1] = [x1, y1, z1, 0];
    run.dispatch(StreamKernel::Frustum, count, stage, &[&order, &bounds, &frustums])?;
    run.next_stage(2)?;
    let root_is_leaf = scene.tree.nodes().first().is_none_or(|r| r.is_leaf());
    let lists = traverse(run, &frustums, count, root_is_leaf)?;
    Ok(GpuPlan { keys, order, bounds, packets: count, frustums, lists })
}

/// The plan's arrays read back, in the core's form.
pub(crate) fn read_plan(run: &mut Run<'_>, plan: &GpuPlan, rays: &[Ray]) -> Result<StreamPlan, Error> {
    let n = rays.len() as u32;
    let p = plan.packets;
    let l = &plan.lists;
    let back = run.read(&[
        (&plan.keys, 0, n),
        (&plan.order, 0, n),
        (&plan.bounds, 0, p + 1),
        (&plan.frustums, 0, FRUSTUM_WORDS * p),
        (&l.frustum, 0, l.len),
        (&l.node, 0, l.len),
        (&l.ranges, 0, 2 * p),
    ])?;
    let mut back = back.into_iter();
    let mut next = || back.next().unwrap_or_default();
    let (keys, order, packets, frustum_words) = (next(), next(), next(), next());
    let frustums: Vec<Frustum> = bytemuck::cast_slice(&frustum_words).to_vec();
    let pairs = PairQueue { frustum: next(), node: next() };
    let ranges = next().chunks_exact(2).map(|r| [r[0], r[1]]).collect();
    let lists = LeafLists { pairs, ranges, queue_sizes: l.queue_sizes.clone(), box_tests: l.box_tests };
    // The device reads rays through `order` and keeps no sorted copy; the core's plan has one.
    // An index out of range (a device fault) shows as an untraceable ray rather than a panic.
    let lost = Ray::new(Vec3::NAN, Vec3::NAN, 0.0, 0.0);
    let sorted_rays = order.iter().map(|&i| rays.get(i as usize).copied().unwrap_or(lost)).collect();
    Ok(StreamPlan { keys, order, sorted_rays, packets, frustums, lists })
}
