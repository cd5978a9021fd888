use super::*;
use crate::bvh2::SahBuilder;
use glam::Vec3;

/// Long slivers crossing the scene diagonally over a grid of small triangles: object splits
/// leave children that overlap along the slivers, the case spatial splits are for.
fn slivers() -> Vec<Triangle> {
    let mut t = Vec::new();
    for i in 0..24 {
        let y = i as f32 * 0.4;
        t.push(Triangle::new(Vec3::new(0.0, y, 0.0), Vec3::new(10.0, y + 3.0, 10.0), Vec3::new(0.0, y + 0.3, 0.1)));
    }
    for i in 0..20 {
        for j in 0..20 {
            let (x, z) = (i as f32 * 0.5, j as f32 * 0.5);
            t.push(Triangle::new(Vec3::new(x, 0.0, z), Vec3::new(x + 0.4, 0.0, z), Vec3::new(x, 0.1, z + 0.4)));
        }
    }
    t
}

fn leaves_of(bvh: &Bvh2, prim: u32) -> Vec<Aabb> {
    bvh.nodes()
        .iter()
        .filter(|n| match n.kind {
            NodeKind::Leaf { first, count } => {
                bvh.prim_order()[first as usize..(first + count) as usize].contains(&prim)
            }
            NodeKind::Internal { .. } => false,
        })
        .map(|n| n.bounds)
        .collect()
}

#[test]
fn cuts_slivers_and_costs_less_than_object_splits_alone() {
    let tris = slivers();
    let sbvh = SbvhBuilder::default().build(&tris).unwrap();
    let sah = SahBuilder::default().build(&tris).unwrap();
    assert!(sbvh.has_split_references(), "the slivers should be cut");
    assert_eq!(sbvh.prim_count(), tris.len());
    assert!(sbvh.prim_order().len() as f32 <= 1.5 * tris.len() as f32, "the budget holds");
    sbvh.check_bounds(&tris).unwrap();
    let cost = SahConfig::default();
    assert!(cost.tree_cost(&sbvh) < cost.tree_cost(&sah), "{} against {}", cost.tree_cost(&sbvh), cost.tree_cost(&sah));
}

#[test]
fn every_point_of_a_triangle_lies_in_a_leaf_that_references_it() {
    let tris = slivers();
    let sbvh = SbvhBuilder::default().build(&tris).unwrap();
    let steps = 24;
    for (p, t) in tris.iter().enumerate() {
        let boxes = leaves_of(&sbvh, p as u32);
        assert!(!boxes.is_empty());
        for i in 0..=steps {
            for j in 0..=steps - i {
                let (u, v) = (i as f32 / steps as f32, j as f32 / steps as f32);
                let q = t.v[0] * (1.0 - u - v) + t.v[1] * u + t.v[2] * v;
                // The point as computed may round off the triangle by an ulp; its box stands in.
                let near = Aabb::new(q - q.abs() * 2.0 * f32::EPSILON, q + q.abs() * 2.0 * f32::EPSILON);
                let overlapped = boxes.iter().any(|b| !Aabb::new(b.min.max(near.min), b.max.min(near.max)).is_empty());
                assert!(overlapped, "triangle {p} at ({u}, {v}) = {q} is in none of its leaves {boxes:?}");
            }
        }
    }
}

#[test]
fn the_vertices_of_every_triangle_lie_in_its_leaves_exactly() {
    let tris = slivers();
    let sbvh = SbvhBuilder::default().build(&tris).unwrap();
    for (p, t) in tris.iter().enumerate() {
        let boxes = leaves_of(&sbvh, p as u32);
        for v in t.v {
            assert!(boxes.iter().any(|b| b.contains(&Aabb::new(v, v))), "vertex {v} of triangle {p}");
        }
    }
}

#[test]
fn without_a_budget_the_tree_is_the_sah_builders() {
    let tris = slivers();
    let config = SbvhConfig { max_references_per_triangle: 1.0, ..SbvhConfig::default() };
    let sbvh = SbvhBuilder::new(config).build(&tris).unwrap();
    let sah = SahBuilder::default().build(&tris).unwrap();
    assert!(!sbvh.has_split_references());
    assert_eq!(sbvh.nodes(), sah.nodes());
    assert_eq!(sbvh.prim_order(), sah.prim_order());
}

#[test]
fn coincident_and_single_triangles_build() {
    let t = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
    let many = SbvhBuilder::default().build(&alloc::vec![t; 100]).unwrap();
    assert!(many.stats().max_leaf_size <= 8);
    many.check_bounds(&alloc::vec![t; 100]).unwrap();
    let one = SbvhBuilder::default().build(&[t]).unwrap();
    assert_eq!(one.len(), 1);
    assert_eq!(SbvhBuilder::default().build(&[]).unwrap_err(), Error::EmptyScene);
}

#[test]
fn a_split_tree_fails_the_bounds_check_of_moved_triangles() {
    let tris = slivers();
    let sbvh = SbvhBuilder::default().build(&tris).unwrap();
    let mut moved = tris.clone();
    moved[3].v[1] += Vec3::new(0.0, 5.0, 0.0);
    assert!(matches!(sbvh.check_bounds(&moved), Err(Error::TreeMismatch { .. })));
    let mut refitted = sbvh.clone();
    refitted.refit(&moved).unwrap();
    refitted.check_bounds(&moved).unwrap();
}
