use glam::Vec3;

/// A triangle by its three vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// The three vertices, in the file's winding order.
    pub v: [Vec3; 3],
}

impl Triangle {
    /// Triangle of three vertices.
    pub fn new(a: Vec3, b: Vec3, c: Vec3) -> Self {
        Self { v: [a, b, c] }
    }

    /// Bounding box.
    pub fn bounds(&self) -> crate::Aabb {
        crate::Aabb::new(self.v[0].min(self.v[1]).min(self.v[2]), self.v[0].max(self.v[1]).max(self.v[2]))
    }

    /// Centroid of the vertices.
    pub fn centroid(&self) -> Vec3 {
        (self.v[0] + self.v[1] + self.v[2]) * (1.0 / 3.0)
    }
}
