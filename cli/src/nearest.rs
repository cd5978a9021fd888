//! `raytrail nearest`: the nearest point on the mesh to each point of a NumPy point file.

use crate::args::{check_distinct, check_input, check_output, load_scene, warn, NearestArgs};
use crate::failure::Outcome;
use crate::flags::builder;
use crate::limits::check_count;
use crate::progress::timed;
use raytrail::core::method::{Method, WideMethod};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::trace::Trace;
use raytrail::cpu::CpuBackend;
use raytrail_cli::npy;
use std::sync::Arc;

/// Bytes a point and its answer take.
const POINT_BYTES: u64 = 12 + 36;

pub fn main(a: NearestArgs) -> Outcome {
    check_output("out", &a.out)?;
    check_input("points", &a.points)?;
    check_input("scene", &a.scene)?;
    check_distinct(&[("points", &a.points), ("scene", &a.scene)], &[("out", &a.out)])?;
    let points = npy::read_points(&a.points).map_err(|e| e.to_string())?;
    check_count("points", points.len() as u64, "max-points", a.max_points, POINT_BYTES)?;
    let (named, _, warning) = load_scene(&a.scene, &a.load.load_options())?;
    warn(&warning);
    let builder = builder(&a.builder);
    crate::args::ploc_note(builder, &named.scene);
    let (bvh, _) = timed("building the BVH2", || builder.build(&named.scene));
    let bvh = bvh.map_err(|e| e.to_string())?;
    // The queries beyond closest and any hit walk the 8-wide tree of least node area.
    let method = Method::Wide(WideMethod::BVH8_SAH);
    let prepared = PreparedScene::new(&named.scene, bvh, &[method]).map_err(|e| e.to_string())?;
    let backend = CpuBackend::new();
    let scene = backend.prepare(Arc::new(prepared)).map_err(|e| e.to_string())?;
    let start = std::time::Instant::now();
    let found = backend.nearest_points(&scene, &points, a.radius).map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    let out = a.out.display();
    npy::write_nearest(&a.out, &found).map_err(|e| e.to_string())?;
    let none = found.iter().filter(|f| f.is_none()).count();
    outln!(
        "{} points, {} without a triangle within {}, {:.2} M points/s, written to {out}",
        points.len(),
        none,
        a.radius,
        points.len() as f64 / seconds.max(1e-9) / 1e6
    );
    Ok(0)
}
