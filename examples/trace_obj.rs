//! Trace a mesh file and print what a few rays hit.
//!
//! ```text
//! cargo run --release --example trace_obj -- path/to/mesh.obj
//! ```
//!
//! Without an argument it traces the Cornell box that ships with the conformance suite. Rays
//! start on a circle around the mesh and point at its centre; each line names the triangle hit,
//! the distance and the hit point.

use raytrail::{Ray, Tracer, Vec3};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/conformance/scenes/cornell_box.obj").into());
    let mesh = raytrail::load(&path)?;
    let tracer = Tracer::from_mesh(&mesh)?;
    println!("{path}: {} triangles", tracer.triangle_count());

    // The mesh's box, from its vertices.
    let (lo, hi) =
        mesh.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let (centre, radius) = ((lo + hi) * 0.5, (hi - lo).length());
    let rays: Vec<Ray> = (0..8)
        .map(|i| {
            let a = i as f32 / 8.0 * std::f32::consts::TAU;
            let origin = centre + Vec3::new(a.cos(), 0.3, a.sin()) * radius;
            Ray::new(origin, centre - origin, 0.0, f32::INFINITY)
        })
        .collect();

    let hits = tracer.intersect(&rays)?;
    for (ray, hit) in rays.iter().zip(&hits) {
        if hit.is_hit() {
            let p = ray.origin() + ray.dir() * hit.t;
            println!("ray from {:>7.2?}: triangle {:>5} at t = {:.4}, point {:.3?}", ray.origin, hit.prim, hit.t, p);
        } else {
            println!("ray from {:>7.2?}: miss", ray.origin);
        }
    }
    Ok(())
}
