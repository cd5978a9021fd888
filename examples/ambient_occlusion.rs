//! Ambient occlusion of a mesh, written as a PNG.
//!
//! ```text
//! cargo run --release --example ambient_occlusion -- [mesh file] [out.png]
//! ```
//!
//! Defaults: the teapot that ships with the conformance suite, and `ambient_occlusion.png`. A
//! camera frames the mesh; each pixel's camera ray finds the closest hit ([`Tracer::intersect`]),
//! then 16 rays over the hemisphere of the hit's normal ask whether anything lies within a fifth
//! of the mesh's size ([`Tracer::occluded`]); the pixel is the share that escape.

use raytrail::{Ray, Tracer, Vec3};

const WIDTH: usize = 320;
const HEIGHT: usize = 240;
const AO_RAYS: usize = 16;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path =
        args.next().unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/conformance/scenes/teapot.obj").into());
    let out = args.next().unwrap_or_else(|| "ambient_occlusion.png".into());
    let mesh = raytrail::load(&path)?;
    let tracer = Tracer::from_mesh(&mesh)?;

    // A camera looking at the mesh's centre from the front and a little above.
    let (lo, hi) =
        mesh.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let (centre, size) = ((lo + hi) * 0.5, (hi - lo).length());
    let eye = centre + Vec3::new(0.0, 0.35, 1.0).normalize() * size * 1.2;
    let forward = (centre - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let camera: Vec<Ray> = (0..WIDTH * HEIGHT)
        .map(|i| {
            let (x, y) = ((i % WIDTH) as f32, (i / WIDTH) as f32);
            let sx = (2.0 * (x + 0.5) / WIDTH as f32 - 1.0) * WIDTH as f32 / HEIGHT as f32 * 0.5;
            let sy = (1.0 - 2.0 * (y + 0.5) / HEIGHT as f32) * 0.5;
            Ray::new(eye, forward + right * sx + up * sy, 0.0, f32::INFINITY)
        })
        .collect();
    let hits = tracer.intersect(&camera)?;

    // AO rays from every hit, over the hemisphere of the triangle's normal facing the camera.
    let mut ao = Vec::with_capacity(hits.len() * AO_RAYS);
    let mut seed = 0x9E37_79B9u32;
    let mut random = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed as f32 / u32::MAX as f32
    };
    for (ray, hit) in camera.iter().zip(&hits).filter(|(_, h)| h.is_hit()) {
        let [a, b, c] = mesh.triangles[hit.prim as usize].map(|v| mesh.positions[v as usize]);
        let mut n = (b - a).cross(c - a).normalize_or_zero();
        if n.dot(ray.dir()) > 0.0 {
            n = -n;
        }
        let p = ray.origin() + ray.dir() * hit.t + n * size * 1e-4;
        for _ in 0..AO_RAYS {
            let d = Vec3::new(random() * 2.0 - 1.0, random() * 2.0 - 1.0, random() * 2.0 - 1.0).normalize_or_zero();
            let d = if d.dot(n) < 0.0 { -d } else { d };
            ao.push(Ray::new(p, d, 0.0, size * 0.2));
        }
    }
    let blocked = tracer.occluded(&ao)?;

    // Background dark grey, so that open surfaces (white) stand out.
    let mut pixels = vec![48u8; WIDTH * HEIGHT];
    let mut next = blocked.chunks(AO_RAYS);
    for (pixel, hit) in pixels.iter_mut().zip(&hits) {
        if hit.is_hit() {
            let open = next.next().map_or(0, |c| c.iter().filter(|&&b| !b).count());
            *pixel = (open * 255 / AO_RAYS) as u8;
        }
    }
    let mut encoder =
        png::Encoder::new(std::io::BufWriter::new(std::fs::File::create(&out)?), WIDTH as u32, HEIGHT as u32);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.write_header()?.write_image_data(&pixels)?;
    let shown = hits.iter().filter(|h| h.is_hit()).count();
    println!(
        "{out}: {WIDTH}x{HEIGHT}, {shown} pixels on the mesh, {} AO rays, {} blocked",
        ao.len(),
        blocked.iter().filter(|&&b| b).count()
    );
    Ok(())
}
