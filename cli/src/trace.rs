//! `raytrail trace` and `raytrail rays`: NumPy files in and out.

use crate::args::{load_scene, warn, write_prim_map, Args, STRICT};
use crate::progress::timed;
use raytrail::conformance::rays::primary;
use raytrail::core::mesh::LoadOptions;
use raytrail::core::method::{Method, Query};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::trace::{Trace, TraceOptions, TriangleTestKind};
use raytrail::core::Hit;
use raytrail::cpu::CpuBackend;
use raytrail::Builder;
use raytrail_cli::npy;
use std::sync::Arc;

pub fn main(args: &[String]) -> Result<i32, String> {
    let a = Args::parse(args, &["any", "moller-trumbore", STRICT])?;
    a.only(&["scene", "rays", "method", "out", "any", "builder", "moller-trumbore", STRICT, "prim-map"])?;
    let method_name = a.get("method").unwrap_or("hash");
    let method = Method::from_name(method_name).ok_or_else(|| {
        format!("unknown method '{method_name}' (known: {})", Method::ALL.map(Method::name).join(", "))
    })?;
    let builder = Builder::from_name(a.get("builder").unwrap_or("sah"))?;
    let scene_path = a.required("scene")?;
    let prim_map = a.get("prim-map");
    let options = LoadOptions { sources: prim_map.is_some(), ..a.load_options() };
    let (named, report, warning) = load_scene(scene_path, &options)?;
    warn(&warning);
    if let Some(map) = prim_map {
        if report.sources.len() != named.scene.triangles().len() {
            return Err(format!("--prim-map: {scene_path} is not a mesh file: there is no source to map to"));
        }
        write_prim_map(map, scene_path, &report)?;
    }
    let rays_path = a.required("rays")?;
    let out = a.required("out")?;
    let rays = npy::read_rays(rays_path).map_err(|e| e.to_string())?;
    let (bvh, _) = timed("building the BVH2", || builder.build(&named.scene));
    let prepared =
        PreparedScene::new(&named.scene, bvh.map_err(|e| e.to_string())?, &[method]).map_err(|e| e.to_string())?;
    let backend = CpuBackend::new();
    let scene = backend.prepare(Arc::new(prepared)).map_err(|e| e.to_string())?;
    let opts = TraceOptions::new(method).query(if a.has("any") { Query::Any } else { Query::Closest }).triangle_test(
        if a.has("moller-trumbore") { TriangleTestKind::MollerTrumbore } else { TriangleTestKind::Watertight },
    );
    let mut hits = vec![Hit::MISS; rays.len()];
    let report = backend.trace(&scene, &rays, &opts, &mut hits).map_err(|e| e.to_string())?;
    npy::write_hits(out, &hits).map_err(|e| e.to_string())?;
    let n_hit = hits.iter().filter(|h| h.is_hit()).count();
    println!("{} rays, {} hits, {:.2} Mrays/s ({method}), written to {out}", rays.len(), n_hit, report.mrays_per_s());
    Ok(0)
}

pub fn rays_main(args: &[String]) -> Result<i32, String> {
    let a = Args::parse(args, &[STRICT])?;
    a.only(&["scene", "out", "width", "height", STRICT])?;
    let (named, _, warning) = load_scene(a.required("scene")?, &a.load_options())?;
    warn(&warning);
    let rays = primary(&named.scene, a.num("width", 320u32)?, a.num("height", 240u32)?);
    let out = a.required("out")?;
    npy::write_rays(out, &rays).map_err(|e| e.to_string())?;
    println!("{} primary rays written to {out}", rays.len());
    Ok(0)
}
