//! Unit icospheres: closed, watertight triangle meshes of a sphere at a chosen subdivision level.

use glam::Vec3;
use std::collections::HashMap;

/// An indexed unit sphere mesh: `20 * 4^level` triangles, counter-clockwise seen from outside.
pub(crate) struct UnitSphere {
    /// Vertices, on the unit sphere.
    pub positions: Vec<Vec3>,
    /// Vertex indices of each triangle.
    pub faces: Vec<[u32; 3]>,
}

/// The icosahedron subdivided `level` times, new vertices pushed out onto the sphere.
pub(crate) fn unit_icosphere(level: u32) -> UnitSphere {
    let mut s = icosahedron();
    for _ in 0..level {
        s = subdivide(&s);
    }
    s
}

/// The regular icosahedron with vertices at the cyclic permutations of `(0, ±1, ±phi)`.
fn icosahedron() -> UnitSphere {
    let phi = (1.0 + 5f32.sqrt()) / 2.0;
    let mut raw = Vec::with_capacity(12);
    for (a, b) in [(-1.0, -phi), (-1.0, phi), (1.0, -phi), (1.0, phi)] {
        raw.push(Vec3::new(0.0, a, b));
        raw.push(Vec3::new(a, b, 0.0));
        raw.push(Vec3::new(b, 0.0, a));
    }
    // Faces are the triples of mutually adjacent vertices (edge length 2), found rather than
    // tabulated; each is then wound to face outward.
    let adjacent = |i: usize, j: usize| ((raw[i] - raw[j]).length() - 2.0).abs() < 1e-3;
    let mut faces = Vec::with_capacity(20);
    for i in 0..12 {
        for j in i + 1..12 {
            for k in j + 1..12 {
                if adjacent(i, j) && adjacent(j, k) && adjacent(i, k) {
                    let n = (raw[j] - raw[i]).cross(raw[k] - raw[i]);
                    let outward = n.dot(raw[i] + raw[j] + raw[k]) > 0.0;
                    faces.push(if outward { [i, j, k] } else { [i, k, j] }.map(|x| x as u32));
                }
            }
        }
    }
    UnitSphere { positions: raw.into_iter().map(Vec3::normalize).collect(), faces }
}

/// Splits each triangle into four at its edge midpoints; a midpoint is made once per edge, so
/// neighbouring triangles share it exactly.
fn subdivide(s: &UnitSphere) -> UnitSphere {
    let mut positions = s.positions.clone();
    let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
    let mut mid = |a: u32, b: u32, positions: &mut Vec<Vec3>| {
        *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
            positions.push((positions[a as usize] + positions[b as usize]).normalize());
            (positions.len() - 1) as u32
        })
    };
    let mut faces = Vec::with_capacity(4 * s.faces.len());
    for &[a, b, c] in &s.faces {
        let ab = mid(a, b, &mut positions);
        let bc = mid(b, c, &mut positions);
        let ca = mid(c, a, &mut positions);
        faces.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
    }
    UnitSphere { positions, faces }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_outward_and_sized() {
        for level in 0..3 {
            let s = unit_icosphere(level);
            assert_eq!(s.faces.len(), 20 * 4usize.pow(level));
            // Euler: V - E + F = 2 with E = 3F/2.
            assert_eq!(s.positions.len(), 2 + s.faces.len() / 2);
            let mut directed = HashMap::new();
            for f in &s.faces {
                let [a, b, c] = f.map(|i| s.positions[i as usize]);
                assert!((b - a).cross(c - a).dot(a + b + c) > 0.0, "face winds inward");
                for k in 0..3 {
                    assert!(directed.insert((f[k], f[(k + 1) % 3]), ()).is_none(), "edge used twice");
                }
            }
            // Every directed edge has its reverse: the mesh is closed and consistently wound.
            assert!(directed.keys().all(|&(a, b)| directed.contains_key(&(b, a))));
        }
    }
}
