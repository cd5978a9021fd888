//! Triangle meshes as loaded, and validated triangle scenes.

use crate::geometry::Triangle;
use crate::{Aabb, Error};
use alloc::vec::Vec;
use glam::Vec3;

/// An indexed triangle mesh as loaded from a file: primitive id = index into `triangles`
/// (file order, polygons fan-split).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// Checks indices and coordinates and gathers the triangles' vertices.
    pub fn to_scene(&self) -> Result<Scene, Error> {
        gather(self.positions.len(), |i| self.positions[i], &self.triangles)
    }
}

/// The scene of `triangles`, each naming its vertices by index, with `vertex(i)` giving the
/// position of vertex `i < vertex_count`: coordinates checked first, then indices.
fn gather(vertex_count: usize, vertex: impl Fn(usize) -> Vec3, triangles: &[[u32; 3]]) -> Result<Scene, Error> {
    if let Some(v) = (0..vertex_count).position(|i| !vertex(i).is_finite()) {
        return Err(Error::NonFiniteVertex { vertex: v });
    }
    let mut tris = Vec::with_capacity(triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        let mut v = [Vec3::ZERO; 3];
        for (slot, &idx) in v.iter_mut().zip(t) {
            if idx as usize >= vertex_count {
                return Err(Error::VertexIndexOutOfRange { triangle: i, index: idx, vertex_count });
            }
            *slot = vertex(idx as usize);
        }
        tris.push(Triangle { v });
    }
    Scene::new(tris)
}

/// A triangle scene ready for building: at least one triangle, all coordinates finite.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    triangles: Vec<Triangle>,
    bounds: Aabb,
}

impl Scene {
    /// A scene of the given triangles (primitive id = index).
    pub fn new(triangles: Vec<Triangle>) -> Result<Scene, Error> {
        if triangles.is_empty() {
            return Err(Error::EmptyScene);
        }
        let mut bounds = Aabb::EMPTY;
        for (i, t) in triangles.iter().enumerate() {
            if t.v.iter().any(|v| !v.is_finite()) {
                return Err(Error::NonFiniteVertex { vertex: 3 * i });
            }
            bounds = bounds.union(t.bounds());
        }
        Ok(Scene { triangles, bounds })
    }

    /// The scene of an indexed mesh held in arrays: `vertices` by position, `triangles` by the
    /// indices of their three vertices (primitive id = index into `triangles`). Fails on a NaN
    /// or infinite coordinate, an index past the vertices, or no triangles.
    pub fn from_indexed(vertices: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<Scene, Error> {
        gather(vertices.len(), |i| Vec3::from_array(vertices[i]), triangles)
    }

    /// The triangles, by primitive id.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// Bounds of all triangles.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }
}
