//! Which of the costly features a scene (and its rays, and the methods chosen for them) needs:
//! 64-bit keys, hash tables, the watertight test's `f64` fallback, the disjoint-interval mask and
//! the slack.

use raytrail_core::key::KeyWidth;
use raytrail_core::method::{Bvh2Method, Method};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::scene::Scene;
use raytrail_core::{Hit, Ray};

/// Whether a feature is needed, and why (a sentence for reports).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Need {
    /// Whether it is needed.
    pub needed: bool,
    /// Why, in the scene's or the methods' terms.
    pub why: String,
}

impl Need {
    fn yes(why: impl Into<String>) -> Need {
        Need { needed: true, why: why.into() }
    }

    fn no(why: impl Into<String>) -> Need {
        Need { needed: false, why: why.into() }
    }
}

/// The decisions for one scene and the methods chosen for it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Needs {
    /// Keys and bit trails of 64 bits (trees deeper than 31 levels, traced by a method that keeps
    /// a key or trail).
    pub keys64: Need,
    /// Perfect-hash tables (a hash method chosen).
    pub hash_tables: Need,
    /// The watertight test's exact `f64` recomputation when an edge function is zero.
    pub f64_fallback: Need,
    /// The disjoint-interval mask (a disjoint method chosen).
    pub disjoint_mask: Need,
    /// The per-ray slack on box intervals.
    pub slack: Need,
}

/// Whether `method` keeps a node key or a bit trail, whose width the tree's depth sets.
pub fn uses_keys(method: Method) -> bool {
    matches!(
        method,
        Method::Bvh2(
            Bvh2Method::ParentSibling
                | Bvh2Method::Uncle
                | Bvh2Method::Hash
                | Bvh2Method::HashDisjoint
                | Bvh2Method::HashResume
        )
    )
}

/// Vertex positions shared by two or more triangles (by exact value, `-0` and `+0` alike), and
/// the number of distinct positions. A ray through a shared vertex or edge must hit exactly one of
/// the triangles there, which is what the exact fallback decides.
pub fn shared_vertices(scene: &Scene) -> (usize, usize) {
    // Sorting the corners' bit patterns finds equal positions without a hash map's overhead; `+
    // 0.0` turns `-0` into `+0`, which are the same point.
    let mut corners: Vec<[u32; 3]> = scene
        .triangles()
        .iter()
        .flat_map(|t| t.v.iter().map(|p| [(p.x + 0.0).to_bits(), (p.y + 0.0).to_bits(), (p.z + 0.0).to_bits()]))
        .collect();
    corners.sort_unstable();
    let (mut shared, mut distinct) = (0, 0);
    let mut i = 0;
    while i < corners.len() {
        let mut j = i + 1;
        while j < corners.len() && corners[j] == corners[i] {
            j += 1;
        }
        distinct += 1;
        shared += usize::from(j - i > 1);
        i = j;
    }
    (shared, distinct)
}

/// Rays of `rays` that every method refuses on the prepared scene `prepared` (outside the
/// supported numeric range, docs/NUMERICS-RANGE.md), as tracing would count them.
pub fn refused_rays(prepared: &PreparedScene, rays: &[Ray]) -> usize {
    let framed = prepared.frame_rays(rays);
    let mut hits = vec![Hit::MISS; rays.len()];
    framed.finish(&mut hits)
}

impl Needs {
    /// Decides for `scene`, whose canonical tree is `depth` levels deep, traced with `chosen`
    /// (the methods chosen per kind of ray); `refused` is, for given rays, how many of how many
    /// are refused ([`refused_rays`]).
    pub fn decide(scene: &Scene, depth: u32, chosen: &[Method], refused: Option<(usize, usize)>) -> Needs {
        let names = |ms: Vec<Method>| ms.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ");
        let width = KeyWidth::for_depth(depth);
        let keyed: Vec<Method> = chosen.iter().copied().filter(|&m| uses_keys(m)).collect();
        let keys64 = match (width, keyed.is_empty()) {
            (Some(KeyWidth::W32), _) => Need::no(format!("the tree is {depth} levels deep: 32-bit keys hold 31")),
            (_, true) => Need::no(format!(
                "the tree is {depth} levels deep, but no chosen method keeps a key or trail (chosen: {})",
                names(chosen.to_vec())
            )),
            (_, false) => Need::yes(format!("the tree is {depth} levels deep and {} keep keys", names(keyed))),
        };
        let hashed: Vec<Method> = chosen.iter().copied().filter(|m| m.needs_hash() || m.needs_full_hash()).collect();
        let hash_tables = if hashed.is_empty() {
            Need::no("no chosen method backtracks through a perfect hash")
        } else {
            Need::yes(format!("{} backtrack through a perfect hash", names(hashed)))
        };
        let (shared, distinct) = shared_vertices(scene);
        let f64_fallback = if shared == 0 {
            Need::no(format!(
                "no two triangles share a vertex ({distinct} distinct positions): no ray can fall between \
                 neighbours, so an edge decided in f32 alone loses nothing"
            ))
        } else {
            Need::yes(format!(
                "{shared} of {distinct} vertex positions are shared: a ray through a shared edge or vertex must hit \
                 exactly one triangle, which only the exact recomputation guarantees"
            ))
        };
        let disjoint: Vec<Method> = chosen
            .iter()
            .copied()
            .filter(|m| matches!(m, Method::Bvh2(Bvh2Method::HashDisjoint | Bvh2Method::StackDisjoint)))
            .collect();
        let disjoint_mask = if disjoint.is_empty() {
            Need::no("no chosen method prunes by the disjoint-interval rule")
        } else {
            Need::yes(format!("{} prune by the disjoint-interval rule", names(disjoint)))
        };
        let tight = "boxes are tight around their triangles, so a triangle's computed t can stray just outside its \
                     box's computed interval; without the slack such hits are lost";
        let slack = match refused {
            Some((refused, n)) => Need::yes(format!(
                "{tight} ({refused} of {n} given rays are refused: outside the range where the slack bounds the error)"
            )),
            None => Need::yes(tight),
        };
        Needs { keys64, hash_tables, f64_fallback, disjoint_mask, slack }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail_core::geometry::Triangle;
    use raytrail_core::glam::Vec3;
    use raytrail_core::method::{KdMethod, WideMethod};

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> Triangle {
        Triangle::new(Vec3::from(a), Vec3::from(b), Vec3::from(c))
    }

    #[test]
    fn shared_vertices_are_counted_by_exact_position() {
        // Two triangles sharing an edge (one corner written as -0), and a lone one.
        let s = Scene::new(vec![
            tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            tri([1.0, 0.0, 0.0], [-0.0, 1.0, 0.0], [1.0, 1.0, 0.0]),
            tri([5.0, 5.0, 5.0], [6.0, 5.0, 5.0], [5.0, 6.0, 5.0]),
        ])
        .unwrap();
        assert_eq!(shared_vertices(&s), (2, 7));
        let needs = Needs::decide(&s, 3, &[Method::Wide(WideMethod::BVH8)], None);
        assert!(needs.f64_fallback.needed);
        // A soup: nothing shared, no fallback needed.
        let soup = Scene::new(vec![s.triangles()[0], s.triangles()[2]]).unwrap();
        assert_eq!(shared_vertices(&soup), (0, 6));
        assert!(!Needs::decide(&soup, 1, &[Method::Wide(WideMethod::BVH8)], None).f64_fallback.needed);
    }

    #[test]
    fn keys_hash_and_mask_follow_the_chosen_methods_and_the_depth() {
        let s = Scene::new(vec![tri([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])]).unwrap();
        let wide = [Method::Wide(WideMethod::BVH8), Method::Kd(KdMethod::Stack)];
        let hash = [Method::Bvh2(Bvh2Method::Hash)];
        // Deep trees need 64-bit keys only where a chosen method keeps a key.
        assert!(!Needs::decide(&s, 40, &wide, None).keys64.needed);
        assert!(Needs::decide(&s, 40, &hash, None).keys64.needed);
        assert!(!Needs::decide(&s, 31, &hash, None).keys64.needed);
        assert!(Needs::decide(&s, 32, &[Method::Bvh2(Bvh2Method::ParentSibling)], None).keys64.needed);
        // Hash tables for the hash methods only; the mask for the disjoint ones only.
        assert!(!Needs::decide(&s, 5, &wide, None).hash_tables.needed);
        assert!(Needs::decide(&s, 5, &hash, None).hash_tables.needed);
        assert!(Needs::decide(&s, 5, &[Method::Bvh2(Bvh2Method::HashResume)], None).hash_tables.needed);
        assert!(!Needs::decide(&s, 5, &hash, None).disjoint_mask.needed);
        assert!(Needs::decide(&s, 5, &[Method::Bvh2(Bvh2Method::HashDisjoint)], None).disjoint_mask.needed);
        assert!(Needs::decide(&s, 5, &[Method::Bvh2(Bvh2Method::StackDisjoint)], None).disjoint_mask.needed);
    }

    #[test]
    fn the_slack_is_always_needed_and_refused_rays_are_counted() {
        let s = Scene::new(vec![tri([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])]).unwrap();
        let bvh = raytrail_core::bvh2::SahBuilder::default().build(s.triangles()).unwrap();
        let p = PreparedScene::new(&s, bvh, &[Method::Bvh2(Bvh2Method::Stack)]).unwrap();
        let ok = Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::new(0.0, 0.0, -1.0), 0.0, f32::INFINITY);
        // A direction so short that distances across the scene overflow: refused.
        let tiny = Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::new(0.0, 0.0, -1e-37), 0.0, f32::INFINITY);
        assert_eq!(refused_rays(&p, &[ok, tiny, ok]), 1);
        let needs = Needs::decide(&s, 1, &[Method::Bvh2(Bvh2Method::Stack)], Some((1, 2)));
        assert!(needs.slack.needed && Needs::decide(&s, 1, &[], None).slack.needed);
        assert!(needs.slack.why.contains("1 of 2 given rays are refused"), "{}", needs.slack.why);
    }
}
