//! The same rays on the CPU and on the GPU (wgpu), hits compared bit for bit.
//!
//! ```text
//! cargo run --release --features gpu --example gpu_trace -- [mesh file]
//! ```
//!
//! Without a GPU adapter (no Vulkan, Metal or DX12 driver; `apt-get install mesa-vulkan-drivers`
//! gives a software one) it says so and exits without error. The GPU backend runs every method;
//! here `bvh8`, through the same [`Trace`] trait as the CPU backend.

use raytrail::core::prepared::PreparedScene;
use raytrail::core::trace::{Trace, TraceOptions};
use raytrail::gpu::WgpuBackend;
use raytrail::{Builder, Hit, Method, Ray, Tracer, Vec3};
use std::sync::Arc;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/conformance/scenes/teapot.obj").into());
    let mesh = raytrail::load(&path)?;
    let scene = mesh.to_scene()?;

    // A grid of rays through the mesh's box, from in front of it.
    let b = scene.bounds();
    let (lo, hi) = (b.min, b.max);
    let rays: Vec<Ray> = (0..256 * 256)
        .map(|i| {
            let (u, v) = ((i % 256) as f32 / 255.0, (i / 256) as f32 / 255.0);
            let target = Vec3::new(lo.x + (hi.x - lo.x) * u, lo.y + (hi.y - lo.y) * v, (lo.z + hi.z) * 0.5);
            let origin = Vec3::new(target.x, target.y, hi.z + (hi.z - lo.z));
            Ray::new(origin, target - origin, 0.0, f32::INFINITY)
        })
        .collect();

    let cpu_hits = Tracer::builder()
        .method(Method::Wide(raytrail::core::method::WideMethod::BVH8))
        .build_scene(&scene)?
        .intersect(&rays)?;

    let backend = match WgpuBackend::new() {
        Ok(b) => b,
        Err(e) => {
            println!("SKIPPED the GPU half: no usable adapter ({e})");
            return Ok(());
        }
    };
    println!("adapter: {}", backend.adapter());
    let method = Method::Wide(raytrail::core::method::WideMethod::BVH8);
    let prepared = Arc::new(PreparedScene::new(&scene, Builder::Best.build(&scene)?, &[method])?);
    let gpu_scene = backend.prepare(prepared)?;
    let mut gpu_hits = vec![Hit::MISS; rays.len()];
    let report = backend.trace(&gpu_scene, &rays, &TraceOptions::new(method), &mut gpu_hits)?;

    let same = cpu_hits.iter().zip(&gpu_hits).filter(|(a, b)| a.same_as(b)).count();
    let hit = gpu_hits.iter().filter(|h| h.is_hit()).count();
    // The first call compiles the kernels, so its time is no measure of speed (`raytrail bench`'s is).
    println!(
        "{} rays, {hit} hits in {:.2} s (kernels compiled in this first call); {same} equal the CPU's bit for bit",
        rays.len(),
        report.seconds
    );
    if same != rays.len() {
        return Err(format!("{} rays differ between the CPU and the GPU", rays.len() - same).into());
    }
    Ok(())
}
