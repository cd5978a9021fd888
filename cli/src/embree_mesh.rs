//! A raytrail scene as an Embree triangle geometry (behind the `embree` feature), shared by the
//! bench's Embree peers and the Embree query bench.

use embree3::{BufferUsage, Device, Error, Format, GeometryBuilder, GeometryKind};
use raytrail::core::scene::Scene;

/// A triangle geometry holding `scene`'s triangles in file order, each with its own three vertices
/// (no sharing), so that Embree's primitive id is raytrail's. Not committed yet: the caller sets
/// what else it needs (a build quality) first.
pub fn triangle_geometry(device: &Device, scene: &Scene) -> Result<GeometryBuilder<'static>, (&'static str, Error)> {
    let tris = scene.triangles();
    let mut geometry = device.create_geometry(GeometryKind::TRIANGLE).map_err(|e| ("cannot create a geometry", e))?;
    {
        let mut vertices = geometry
            .set_new_buffer::<[f32; 3]>(BufferUsage::VERTEX, 0, Format::FLOAT3, 12, 3 * tris.len())
            .map_err(|e| ("cannot make the vertex buffer", e))?;
        write_vertices(&mut vertices, scene);
    }
    {
        let mut indices = geometry
            .set_new_buffer::<[u32; 3]>(BufferUsage::INDEX, 0, Format::UINT3, 12, tris.len())
            .map_err(|e| ("cannot make the index buffer", e))?;
        for (i, out) in indices.iter_mut().enumerate() {
            let k = 3 * i as u32;
            *out = [k, k + 1, k + 2];
        }
    }
    Ok(geometry)
}

/// `scene`'s vertices in the unshared layout of [`triangle_geometry`] (three per triangle), for a
/// vertex buffer written again when the vertices move.
pub fn write_vertices(out: &mut [[f32; 3]], scene: &Scene) {
    for (out, t) in out.chunks_exact_mut(3).zip(scene.triangles()) {
        for (o, v) in out.iter_mut().zip(&t.v) {
            *o = v.to_array();
        }
    }
}
