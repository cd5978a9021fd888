//! `raytrail render`: a picture of what was traced. Primary rays in raster order (row by row,
//! top-left first) through the outside or inside camera of `bench`; the image shows the hit
//! triangles' normals, ambient occlusion, or a heat map of the traversal work per pixel (nodes
//! visited by `--method`, from its per-ray node enumeration), so methods can be compared by eye.

use crate::args::{check_distinct, check_input, check_output, load_scene, warn, RenderArgs};
use crate::bench::rays::{facing_normal, AoShape};
use crate::bench::view::View;
use crate::failure::Outcome;
use crate::flags::{builder, method_or_auto};
use crate::limits::{check_image, try_vec};
use crate::progress::timed;
use crate::trace::raster_rays;
use glam::Vec3;
use raytrail::core::method::{Method, Query};
use raytrail::core::scene::Scene;
use raytrail::core::trace::{Record, Trace, TraceOptions};
use raytrail::core::{Hit, Ray};
use raytrail::cpu::CpuBackend;
use raytrail_cli::write::write_atomically;
use raytrail_conformance::rng::Pcg32;
use std::sync::Arc;

/// Background of pixels whose ray hits nothing (normals and ao).
const BACKGROUND: [u8; 3] = [24, 24, 32];

/// Rays per batch of the heat map: their node enumerations are held at once.
const HEAT_BATCH: usize = 1 << 14;

/// Something that traces a batch of rays: the CPU backend, or the GPU's.
type Tracer<'a> = dyn Fn(&[Ray], Query, &mut [Hit]) -> Result<(), String> + 'a;

pub fn main(a: RenderArgs) -> Outcome {
    check_output("out", &a.out)?;
    let (width, height) = (a.width, a.height);
    // Per pixel: the ray, its hit, the colour, and the AO rays and hits of one pixel row at a time.
    let per_pixel = (std::mem::size_of::<Ray>() + std::mem::size_of::<Hit>() + 3) as u64;
    let pixels = check_image(width, height, "pixels", "max-pixels", a.max_pixels, per_pixel)? as usize;
    check_input("scene", &a.scene)?;
    check_distinct(&[("scene", &a.scene)], &[("out", &a.out)])?;
    let method = method_or_auto(&a.method);
    let heat = a.mode == "heat" || a.mode == "backtracks";
    if heat && a.backend == "gpu" {
        return crate::failure::usage(format!(
            "--mode {} runs on the CPU (the work per ray is recorded there): leave out --backend gpu",
            a.mode
        ));
    }
    let (loaded, _) = timed(&format!("loading {}", a.scene.display()), || load_scene(&a.scene, &a.load.load_options()));
    let (named, _, warning) = loaded?;
    warn(&warning);
    let scene = &named.scene;
    crate::args::ploc_note(builder(&a.builder), scene);
    let (bvh, _) = timed(&format!("building the BVH2 ({} triangles)", scene.triangles().len()), || {
        builder(&a.builder).build(scene)
    });
    let bvh = bvh.map_err(|e| e.to_string())?;
    let view = if a.camera == "inside" { View::Inside } else { View::Outside };
    let camera = view.camera(scene.bounds());
    let rays = raster_rays(&camera, width, height);
    debug_assert_eq!(rays.len(), pixels);

    let cpu_backend = CpuBackend::new();
    // Auto chooses for the image's own rays, as `trace` does for its file's.
    let (prepared, method) = crate::auto::prepare_for(scene, bvh, method, &rays, Query::Closest, &cpu_backend)?;
    let prepared = Arc::new(prepared);
    let cpu = cpu_backend.prepare(prepared.clone()).map_err(|e| e.to_string())?;
    let image = if heat {
        let what = if a.mode == "heat" { "nodes visited" } else { "backtracking steps" };
        let (counts, _) = timed(&format!("tracing {pixels} rays ({method}), recording the {what}"), || {
            if a.mode == "heat" {
                nodes_per_ray(&cpu_backend, &cpu, &rays, method)
            } else {
                backtracks_per_ray(&cpu_backend, &cpu, &rays, method)
            }
        });
        let counts = counts?;
        let (lo, hi) = (counts.iter().copied().min().unwrap_or(0), counts.iter().copied().max().unwrap_or(0));
        let mean = counts.iter().map(|&c| c as f64).sum::<f64>() / counts.len().max(1) as f64;
        outln!("{what} per pixel ({method}): min {lo}, mean {mean:.2}, max {hi} (colour scale: log, 0 to {hi})");
        heat_image(&counts, hi)?
    } else {
        let gpu;
        let tracer: Box<Tracer<'_>> = if a.backend == "gpu" {
            gpu = crate::gpu::Gpu::open(prepared.clone()).map_err(|e| format!("--backend gpu: {e}"))?;
            Box::new(move |rays: &[Ray], query, hits: &mut [Hit]| gpu.trace(rays, method, query, hits))
        } else {
            Box::new(|rays: &[Ray], query, hits: &mut [Hit]| {
                let opts = TraceOptions::new(method).query(query);
                cpu_backend.trace(&cpu, rays, &opts, hits).map(|_| ()).map_err(|e| e.to_string())
            })
        };
        let mut hits = try_vec(rays.len(), Hit::MISS, "hits")?;
        let (traced, _) =
            timed(&format!("tracing {pixels} primary rays ({method})"), || tracer(&rays, Query::Closest, &mut hits));
        traced?;
        if a.mode == "ao" {
            let (img, _) = timed(&format!("tracing {} ambient-occlusion rays per pixel", a.ao_rays), || {
                ao_image(&*tracer, scene, &rays, &hits, width as usize, a.ao_rays as usize)
            });
            img?
        } else {
            normals_image(scene, &rays, &hits)?
        }
    };
    write_png(&a.out, width, height, &image)?;
    outln!(
        "{width} x {height} {} image of {} ({method}, {} camera) written to {}",
        a.mode,
        named.name,
        a.camera,
        a.out.display()
    );
    Ok(0)
}

/// Nodes each ray visits under `method`: the length of its node enumeration.
fn nodes_per_ray(
    backend: &CpuBackend,
    cpu: &raytrail::cpu::CpuScene,
    rays: &[Ray],
    method: Method,
) -> Result<Vec<u32>, String> {
    let opts = TraceOptions::new(method).record(Record::Enumerations);
    let mut counts = try_vec(rays.len(), 0u32, "node counts").map_err(|e| e.message().to_string())?;
    let mut hits = vec![Hit::MISS; HEAT_BATCH.min(rays.len())];
    for (chunk, out) in rays.chunks(HEAT_BATCH).zip(counts.chunks_mut(HEAT_BATCH)) {
        let report = backend.trace(cpu, chunk, &opts, &mut hits[..chunk.len()]).map_err(|e| e.to_string())?;
        let lists = report.enumerations.ok_or("the backend recorded no node enumeration")?;
        for (c, list) in out.iter_mut().zip(&lists) {
            *c = u32::try_from(list.len()).unwrap_or(u32::MAX);
        }
    }
    Ok(counts)
}

/// Backtracking steps of each ray under `method`: its work counters, one ray per trace (the
/// counters are summed over a batch), the rays spread over the threads.
fn backtracks_per_ray(
    backend: &CpuBackend,
    cpu: &raytrail::cpu::CpuScene,
    rays: &[Ray],
    method: Method,
) -> Result<Vec<u32>, String> {
    use rayon::prelude::*;
    let opts = TraceOptions::new(method).record(Record::Counters);
    let mut counts = try_vec(rays.len(), 0u32, "step counts").map_err(|e| e.message().to_string())?;
    counts.par_iter_mut().zip(rays.par_iter()).try_for_each(|(c, ray)| {
        let mut hit = [Hit::MISS];
        let report = backend.trace(cpu, std::slice::from_ref(ray), &opts, &mut hit).map_err(|e| e.to_string())?;
        *c = u32::try_from(report.counters.unwrap_or_default().backtracks).unwrap_or(u32::MAX);
        Ok::<(), String>(())
    })?;
    Ok(counts)
}

/// Each pixel coloured by its hit triangle's facing normal (`0.5 + 0.5 n` as RGB), dimmed by the
/// angle to the ray, so that shapes read as in a shaded image.
fn normals_image(scene: &Scene, rays: &[Ray], hits: &[Hit]) -> Result<Vec<u8>, String> {
    let mut img = try_vec(rays.len() * 3, 0u8, "image bytes").map_err(|e| e.message().to_string())?;
    for ((px, ray), hit) in img.chunks_exact_mut(3).zip(rays).zip(hits) {
        let rgb = match facing_normal(scene, ray, hit) {
            Some(n) => {
                let light = 0.35 + 0.65 * (-n.dot(ray.dir())).clamp(0.0, 1.0);
                let c = (n * 0.5 + Vec3::splat(0.5)) * light * 255.0;
                [c.x as u8, c.y as u8, c.z as u8]
            }
            None => BACKGROUND,
        };
        px.copy_from_slice(&rgb);
    }
    Ok(img)
}

/// Ambient occlusion: from each hit point, `per_pixel` rays as the bench makes them
/// ([`AoShape::push_rays`]), a tenth of the scene's diagonal long; the pixel's grey is the share
/// that escapes. Traced one row of pixels at a time.
fn ao_image(
    tracer: &Tracer<'_>,
    scene: &Scene,
    rays: &[Ray],
    hits: &[Hit],
    width: usize,
    per_pixel: usize,
) -> Result<Vec<u8>, String> {
    let shape = AoShape::of(scene, 0.1, per_pixel);
    let mut img = try_vec(rays.len() * 3, 0u8, "image bytes").map_err(|e| e.message().to_string())?;
    let mut ao_rays = Vec::with_capacity(width * per_pixel);
    let mut ao_hits = Vec::with_capacity(width * per_pixel);
    for (row, (row_rays, row_hits)) in rays.chunks(width).zip(hits.chunks(width)).enumerate() {
        ao_rays.clear();
        let mut owners = Vec::with_capacity(width);
        for (col, (ray, hit)) in row_rays.iter().zip(row_hits).enumerate() {
            // Each pixel its own random stream, so the image does not depend on the row size.
            let mut rng = Pcg32::new(RENDER_SEED, (row * width + col) as u64);
            if shape.push_rays(scene, ray, hit, &mut rng, &mut ao_rays) {
                owners.push(col);
            }
        }
        ao_hits.clear();
        ao_hits.resize(ao_rays.len(), Hit::MISS);
        tracer(&ao_rays, Query::Any, &mut ao_hits)?;
        let row_px = &mut img[row * width * 3..(row * width + row_rays.len()) * 3];
        for px in row_px.chunks_exact_mut(3) {
            px.copy_from_slice(&BACKGROUND);
        }
        for (k, &col) in owners.iter().enumerate() {
            let open = ao_hits[k * per_pixel..(k + 1) * per_pixel].iter().filter(|h| !h.is_hit()).count();
            let g = (255.0 * open as f32 / per_pixel as f32) as u8;
            row_px[col * 3..col * 3 + 3].copy_from_slice(&[g, g, g]);
        }
    }
    Ok(img)
}

/// The random streams of the rendered ambient occlusion.
const RENDER_SEED: u64 = 0x5EED;

/// The heat map: nodes visited on a log scale from dark blue (none) through cyan, green and yellow
/// to red (`max`).
fn heat_image(counts: &[u32], max: u32) -> Result<Vec<u8>, String> {
    let mut img = try_vec(counts.len() * 3, 0u8, "image bytes").map_err(|e| e.message().to_string())?;
    let scale = (1.0 + max as f32).ln().max(1e-6);
    for (px, &c) in img.chunks_exact_mut(3).zip(counts) {
        px.copy_from_slice(&heat_colour((1.0 + c as f32).ln() / scale));
    }
    Ok(img)
}

/// A colour for `x` in `[0, 1]`: dark blue, blue, cyan, green, yellow, red.
fn heat_colour(x: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 6] =
        [[0.0, 0.0, 0.25], [0.0, 0.2, 1.0], [0.0, 0.9, 1.0], [0.1, 0.9, 0.2], [1.0, 0.95, 0.0], [0.9, 0.05, 0.0]];
    let x = x.clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (x as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    let c = |k: usize| ((STOPS[i][k] * (1.0 - f) + STOPS[i + 1][k] * f) * 255.0).round() as u8;
    [c(0), c(1), c(2)]
}

/// Writes an 8-bit RGB PNG, atomically.
fn write_png(path: &std::path::Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), String> {
    write_atomically(path, |w| {
        let mut encoder = png::Encoder::new(w, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
        writer.write_image_data(rgb).map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    })
    .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heat_colours_run_from_blue_to_red() {
        assert_eq!(heat_colour(0.0), [0, 0, 64]);
        assert_eq!(heat_colour(1.0), [230, 13, 0]);
        assert!(heat_colour(0.5)[1] > 200);
    }
}
