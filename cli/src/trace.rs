//! `raytrail trace` and `raytrail rays`: NumPy files in and out.

use crate::args::{check_distinct, check_input, check_output, load_scene, warn, write_prim_map};
use crate::args::{RaysArgs, TraceArgs};
use crate::failure::{Failure, Outcome};
use crate::flags::{builder, method_or_auto};
use crate::limits::{check_count, check_image, try_vec};
use crate::progress::timed;
use raytrail::core::bvh2::Bvh2;
use raytrail::core::instance::{trace_instanced, InstancedScene};
use raytrail::core::method::{Method, Query, WideMethod};
use raytrail::core::prepared::PreparedScene;
use raytrail::core::scene::Scene;
use raytrail::core::trace::{Trace, TraceOptions, TriangleTestKind};
use raytrail::core::{Hit, Ray};
use raytrail::cpu::CpuBackend;
use raytrail::mesh::LoadOptions;
use raytrail::{AllHitsOptions, InstanceHit};
use raytrail_cli::npy;
use raytrail_conformance::rays::{primary_from, Camera};
use std::sync::Arc;

/// Bytes a traced ray takes: the ray and its hit.
const RAY_AND_HIT_BYTES: u64 = (std::mem::size_of::<Ray>() + std::mem::size_of::<Hit>()) as u64;

pub fn main(a: TraceArgs) -> Outcome {
    let method = method_or_auto(&a.method);
    let builder = builder(&a.builder);
    // Every output location and input file is checked before any work.
    check_output("out", &a.out)?;
    if let Some(map) = &a.prim_map {
        check_output("prim-map", map)?;
    }
    check_input("rays", &a.rays)?;
    check_input("scene", &a.scene)?;
    let mut inputs = vec![("rays", a.rays.as_path()), ("scene", a.scene.as_path())];
    if let Some(masks) = &a.masks {
        if !crate::instances::is_instance_file(&a.scene) {
            return Err(Failure::Usage(
                "--masks needs a scene file of instances (.json): a mesh's triangles carry no masks".into(),
            ));
        }
        check_input("masks", masks)?;
        inputs.push(("masks", masks.as_path()));
    }
    let mut outputs = vec![("out", a.out.as_path())];
    outputs.extend(a.prim_map.as_deref().map(|m| ("prim-map", m)));
    check_distinct(&inputs, &outputs)?;
    let rays = npy::read_rays(&a.rays).map_err(|e| e.to_string())?;
    check_count("rays", rays.len() as u64, "max-rays", a.max_rays, RAY_AND_HIT_BYTES)?;
    if crate::instances::is_instance_file(&a.scene) {
        return instanced(&a, &rays, &outputs);
    }
    let scene_path = a.scene.as_path();
    let options = LoadOptions { sources: a.prim_map.is_some(), ..a.load.load_options() };
    let (named, report, warning) = load_scene(scene_path, &options)?;
    warn(&warning);
    if let Some(map) = &a.prim_map {
        if report.sources.len() != named.scene.triangles().len() {
            let shown = scene_path.display();
            return Err(format!("--prim-map: {shown} is not a mesh file: there is no source to map to").into());
        }
        write_prim_map(map, scene_path, &report)?;
    }
    crate::args::ploc_note(builder, &named.scene);
    let (bvh, _) = timed("building the BVH2", || builder.build(&named.scene));
    let bvh = bvh.map_err(|e| e.to_string())?;
    let backend = CpuBackend::new();
    if a.all {
        return all_hits(&a, &named.scene, bvh, &rays, &backend);
    }
    let query = if a.any { Query::Any } else { Query::Closest };
    let (prepared, method) = crate::auto::prepare_for(&named.scene, bvh, method, &rays, query, &backend)?;
    let scene = backend.prepare(Arc::new(prepared)).map_err(|e| e.to_string())?;
    let opts = TraceOptions::new(method).query(query).triangle_test(if a.moller_trumbore {
        TriangleTestKind::MollerTrumbore
    } else {
        TriangleTestKind::Watertight
    });
    let mut hits = try_vec(rays.len(), Hit::MISS, "hits")?;
    let report = backend.trace(&scene, &rays, &opts, &mut hits).map_err(|e| e.to_string())?;
    let out = a.out.display();
    npy::write_hits(&a.out, &hits).map_err(|e| e.to_string())?;
    let n_hit = hits.iter().filter(|h| h.is_hit()).count();
    outln!(
        "{} rays, {} hits, {} refused, {:.2} Mrays/s ({method}), written to {out}",
        rays.len(),
        n_hit,
        report.refused,
        report.mrays_per_s()
    );
    if report.refused > 0 {
        // Refused rays are not misses: they are outside the supported range (docs/NUMERICS-RANGE.md)
        // and marked in the hits file with t = NaN, prim = 0xFFFFFFFE.
        outln!("  {} rays refused: outside the supported numeric range (docs/NUMERICS-RANGE.md)", report.refused);
    }
    Ok(0)
}

/// `trace` on a scene file of instances ([`crate::instances`]): closest or any hits, each with
/// its instance's id, by the named method (`auto` is the single-ray walk of the 8-wide tree of
/// least node area, which suits the per-instance batches instancing makes).
fn instanced(a: &TraceArgs, rays: &[Ray], outputs: &[(&str, &std::path::Path)]) -> Outcome {
    if a.all || a.prim_map.is_some() {
        let flag = if a.all { "--all" } else { "--prim-map" };
        return Err(Failure::Usage(format!("{flag} is not available for a scene file of instances")));
    }
    let masks = match &a.masks {
        Some(path) => {
            let masks = npy::read_masks(path).map_err(|e| e.to_string())?;
            if masks.len() != rays.len() {
                return Err(format!(
                    "--masks {} holds {} masks for the {} rays of --rays {}: one mask per ray",
                    path.display(),
                    masks.len(),
                    rays.len(),
                    a.rays.display()
                )
                .into());
            }
            Some(masks)
        }
        None => None,
    };
    let file = crate::instances::load_instances(&a.scene, &a.load.load_options())?;
    let inputs: Vec<(&str, &std::path::Path)> = file.mesh_paths.iter().map(|p| ("scene", p.as_path())).collect();
    check_distinct(&inputs, outputs)?;
    let builder = builder(&a.builder);
    let method = method_or_auto(&a.method).unwrap_or(raytrail::INSTANCED_DEFAULT);
    let backend = CpuBackend::new();
    let (meshes, _) = timed("building the meshes' trees", || {
        file.meshes
            .iter()
            .map(|scene| Ok(Arc::new(PreparedScene::new(scene, builder.build(scene)?, &[method])?)))
            .collect::<Result<Vec<_>, raytrail::Error>>()
    });
    let meshes = meshes.map_err(|e| e.to_string())?;
    let scene = InstancedScene::prepare(&backend, &meshes, &file.instances)
        .map_err(|e| format!("{}: {e}", a.scene.display()))?;
    let query = if a.any { Query::Any } else { Query::Closest };
    let opts = TraceOptions::new(method).query(query).triangle_test(if a.moller_trumbore {
        TriangleTestKind::MollerTrumbore
    } else {
        TriangleTestKind::Watertight
    });
    let mut hits = try_vec(rays.len(), InstanceHit::MISS, "hits")?;
    let start = std::time::Instant::now();
    let report =
        trace_instanced(&backend, &scene, rays, masks.as_deref(), &opts, &mut hits).map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    npy::write_instance_hits(&a.out, &hits).map_err(|e| e.to_string())?;
    let n_hit = hits.iter().filter(|h| h.is_hit()).count();
    outln!(
        "{} rays, {} hits on {} instances of {} meshes ({} triangles instanced), {} refused, {:.2} Mrays/s ({method}), written to {}",
        rays.len(),
        n_hit,
        file.instances.len(),
        file.meshes.len(),
        file.instanced_triangles(),
        report.report.refused,
        rays.len() as f64 / seconds.max(1e-9) / 1e6,
        a.out.display()
    );
    Ok(0)
}

/// `trace --all`: every hit along each ray from the 8-wide tree of least node area, written one
/// record per hit with its ray's index.
fn all_hits(a: &TraceArgs, scene: &Scene, bvh: Bvh2, rays: &[Ray], backend: &CpuBackend) -> Outcome {
    let method = Method::Wide(WideMethod::BVH8_SAH);
    let prepared = PreparedScene::new(scene, bvh, &[method]).map_err(|e| e.to_string())?;
    let cpu = backend.prepare(Arc::new(prepared)).map_err(|e| e.to_string())?;
    let options = AllHitsOptions { max_hits: a.max_hits.unwrap_or(usize::MAX), merge_equal_t: a.merge_equal_t };
    let start = std::time::Instant::now();
    let lists = backend.all_hits(&cpu, rays, &options).map_err(|e| e.to_string())?;
    let seconds = start.elapsed().as_secs_f64();
    let out = a.out.display();
    npy::write_hit_lists(&a.out, &lists).map_err(|e| e.to_string())?;
    let refused = lists.iter().filter(|l| l.first().is_some_and(Hit::is_refused)).count();
    let truncated = (0..lists.len()).filter(|&i| lists.is_truncated(i)).count();
    let hit = lists.iter().filter(|l| !l.is_empty()).count() - refused;
    outln!(
        "{} rays, {} hits on {} rays, {} refused, {} truncated at --max-hits, {:.2} Mrays/s, written to {out}",
        rays.len(),
        lists.hits().len() - refused,
        hit,
        refused,
        truncated,
        rays.len() as f64 / seconds.max(1e-9) / 1e6
    );
    Ok(0)
}

/// Primary rays of `camera` through the pixel centers of a `width` x `height` image in raster
/// order: row by row from the top, each row left to right, so ray `i` is pixel
/// `(i % width, i / width)`.
pub fn raster_rays(camera: &Camera, width: u32, height: u32) -> Vec<Ray> {
    (0..height)
        .flat_map(|y| (0..width).map(move |x| camera.ray(x as f32 + 0.5, y as f32 + 0.5, width, height)))
        .collect()
}

pub fn rays_main(a: RaysArgs) -> Outcome {
    check_output("out", &a.out)?;
    // The rays, and the pixel list Morton order sorts.
    check_image(a.width, a.height, "rays", "max-rays", a.max_rays, std::mem::size_of::<Ray>() as u64 + 8)?;
    check_input("scene", &a.scene)?;
    check_distinct(&[("scene", &a.scene)], &[("out", &a.out)])?;
    let (named, _, warning) = load_scene(&a.scene, &a.load.load_options())?;
    warn(&warning);
    let camera = Camera::framing(named.scene.bounds());
    let rays = if a.order == "raster" {
        raster_rays(&camera, a.width, a.height)
    } else {
        primary_from(&camera, a.width, a.height)
    };
    let out = a.out.display();
    npy::write_rays(&a.out, &rays).map_err(|e| e.to_string())?;
    outln!("{} primary rays ({} order) written to {out}", rays.len(), a.order);
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail_conformance::rays::morton_order;

    #[test]
    fn raster_order_is_morton_order_reordered() {
        let camera = Camera::framing(raytrail::core::Aabb::new(glam::Vec3::ZERO, glam::Vec3::ONE));
        let (w, h) = (7, 5);
        let raster = raster_rays(&camera, w, h);
        let morton = primary_from(&camera, w, h);
        for (i, (x, y)) in morton_order(w, h).into_iter().enumerate() {
            assert_eq!(raster[(y * w + x) as usize], morton[i]);
        }
    }
}
