//! Shadow queries: which points on a floor see a point light past an occluder.
//!
//! ```text
//! cargo run --release --example shadows
//! ```
//!
//! A floor and a square occluder above it are given as arrays in memory; one shadow ray per
//! floor sample asks [`Tracer::occluded`] whether anything lies between the sample and the light,
//! and the shadow is printed as a character map (`#` in shadow, `.` lit).

use raytrail::{Ray, Tracer, Vec3};

fn main() -> Result<(), raytrail::Error> {
    // A 4 x 4 floor at y = 0 and a 1 x 1 occluder at y = 1 (two triangles each).
    let vertices = [
        [-2.0, 0.0, -2.0],
        [2.0, 0.0, -2.0],
        [2.0, 0.0, 2.0],
        [-2.0, 0.0, 2.0],
        [-0.5, 1.0, -0.5],
        [0.5, 1.0, -0.5],
        [0.5, 1.0, 0.5],
        [-0.5, 1.0, 0.5],
    ];
    let triangles = [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
    let tracer = Tracer::new(&vertices, &triangles)?;

    let light = Vec3::new(0.0, 3.0, 0.0);
    let (columns, lines) = (48, 25);
    let mut rays = Vec::with_capacity(columns * lines);
    for j in 0..lines {
        for i in 0..columns {
            let p = Vec3::new(
                -2.0 + 4.0 * (i as f32 + 0.5) / columns as f32,
                0.0,
                -2.0 + 4.0 * (j as f32 + 0.5) / lines as f32,
            );
            // From just above the floor toward the light, stopping short of it: t in [0, 1) spans
            // the segment when the direction is the full offset.
            let from = p + Vec3::new(0.0, 1e-4, 0.0);
            rays.push(Ray::new(from, light - from, 0.0, 1.0));
        }
    }
    let shadowed = tracer.occluded(&rays)?;
    for row in shadowed.chunks(columns) {
        println!("{}", row.iter().map(|&s| if s { '#' } else { '.' }).collect::<String>());
    }
    let count = shadowed.iter().filter(|&&s| s).count();
    println!("{count} of {} floor samples are in shadow", rays.len());
    // The occluder (side 1, two units below the light) casts a centred square of side 1.5 on the
    // floor (three units below it); no sample lies within 0.04 of that square's edges.
    let inside = rays.iter().filter(|r| r.origin[0].abs() < 0.75 && r.origin[2].abs() < 0.75).count();
    assert_eq!(count, inside, "the shadow is the occluder's projection");
    Ok(())
}
