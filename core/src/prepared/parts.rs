//! The parts a prepared scene can hold, which methods read which, what each costs, and dropping
//! the parts no remaining method reads.

use super::PreparedScene;
use crate::method::{Bvh2Method, Method, StreamMethod, WideMethod, WideTreeKind};
use core::fmt;

/// One table (or set of tables) [`PreparedScene::new`] derives from the canonical tree. The
/// canonical tree itself is not a part: every scene keeps it (it names nodes in enumerations).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Part {
    /// The Aila-Laine layout with uncle links, and its leaf triangles.
    UncleLayout,
    /// The Aila-Laine layout with parent and sibling links, and its leaf triangles.
    ParentLayout,
    /// The perfect hash over backtracking targets.
    Hash,
    /// The perfect hash over every node.
    FullHash,
    /// The kd-tree, its primitive references and a copy of the triangles.
    Kd,
    /// The 4-wide tree by Guthe's pull-up.
    Wide4,
    /// The perfect hash over the 4-wide tree's node keys.
    Wide4Hash,
    /// The 8-wide tree by the pull-up.
    Wide8,
    /// The 4-wide tree with every second binary level removed.
    Wide4Naive,
    /// The 8-wide tree by the SAH-optimal cut.
    Wide8Sah,
    /// The 8-wide tree stored level by level (the stream method's).
    Levels,
}

impl Part {
    /// Every part, in the order [`PreparedScene::new`] builds them.
    pub const ALL: [Part; 11] = [
        Part::UncleLayout,
        Part::ParentLayout,
        Part::Hash,
        Part::FullHash,
        Part::Kd,
        Part::Wide4,
        Part::Wide4Hash,
        Part::Wide8,
        Part::Wide4Naive,
        Part::Wide8Sah,
        Part::Levels,
    ];

    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Part::UncleLayout => "uncle layout",
            Part::ParentLayout => "parent/sibling layout",
            Part::Hash => "hash (backtracking targets)",
            Part::FullHash => "hash (every node)",
            Part::Kd => "kd-tree",
            Part::Wide4 => "4-wide tree",
            Part::Wide4Hash => "hash (4-wide node keys)",
            Part::Wide8 => "8-wide tree",
            Part::Wide4Naive => "4-wide tree (naive)",
            Part::Wide8Sah => "8-wide tree (SAH-optimal cut)",
            Part::Levels => "level-order 8-wide tree",
        }
    }

    /// The parts `method` reads; [`PreparedScene::new`] builds exactly the union of these over
    /// the methods it is given.
    pub fn of(method: Method) -> &'static [Part] {
        match method {
            Method::Bvh2(Bvh2Method::ParentSibling) => &[Part::ParentLayout],
            Method::Bvh2(Bvh2Method::Hash | Bvh2Method::HashDisjoint) => &[Part::UncleLayout, Part::Hash],
            Method::Bvh2(Bvh2Method::HashResume) => &[Part::UncleLayout, Part::FullHash],
            Method::Bvh2(_) => &[Part::UncleLayout],
            Method::Kd(_) => &[Part::Kd],
            Method::Wide(WideMethod::BVH4_HASH) => &[Part::Wide4, Part::Wide4Hash],
            Method::Wide(m) => match m.tree() {
                WideTreeKind::Four => &[Part::Wide4],
                WideTreeKind::FourNaive => &[Part::Wide4Naive],
                WideTreeKind::Eight => &[Part::Wide8],
                WideTreeKind::EightSah => &[Part::Wide8Sah],
            },
            Method::Stream(StreamMethod::Frustum8) => &[Part::Levels],
        }
    }

    /// Whether any of `methods` reads this part.
    pub fn needed_by(self, methods: &[Method]) -> bool {
        methods.iter().any(|&m| Part::of(m).contains(&self))
    }
}

impl fmt::Display for Part {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl PreparedScene {
    /// Bytes of `part`, or `None` where this scene was prepared without it.
    pub fn part_bytes(&self, part: Part) -> Option<usize> {
        match part {
            Part::UncleLayout => self.uncles.as_ref().map(|l| l.bytes()),
            Part::ParentLayout => self.parents.as_ref().map(|l| l.bytes()),
            Part::Hash => self.hash.as_ref().map(|h| h.stats.bytes),
            Part::FullHash => self.full_hash.as_ref().map(|h| h.stats.bytes),
            Part::Kd => self.kd.as_ref().map(|k| k.tree.bytes() + core::mem::size_of_val(k.triangles.as_slice())),
            Part::Wide4 => self.wide4.as_ref().map(|t| t.bytes()),
            // A tree too deep for keys holds no tables.
            Part::Wide4Hash => self.wide4_hash.as_ref().map(|h| h.as_ref().map_or(0, |h| h.hash.stats.bytes)),
            Part::Wide8 => self.wide8.as_ref().map(|t| t.bytes()),
            Part::Wide4Naive => self.wide4_naive.as_ref().map(|t| t.bytes()),
            Part::Wide8Sah => self.wide8_sah.as_ref().map(|t| t.bytes()),
            Part::Levels => self.levels.as_ref().map(|t| t.bytes()),
        }
    }

    /// Bytes of every part `method` reads, or `None` where one of them was not prepared.
    pub fn method_bytes(&self, method: Method) -> Option<usize> {
        Part::of(method).iter().map(|&p| self.part_bytes(p)).sum()
    }

    /// Drops every part none of `methods` reads (after [`PreparedScene::new`] was given more
    /// methods than end up traced, as when a method is chosen by measuring several). The
    /// canonical tree stays.
    pub fn retain_parts_for(&mut self, methods: &[Method]) {
        for part in Part::ALL {
            if part.needed_by(methods) {
                continue;
            }
            match part {
                Part::UncleLayout => self.uncles = None,
                Part::ParentLayout => self.parents = None,
                Part::Hash => self.hash = None,
                Part::FullHash => self.full_hash = None,
                Part::Kd => self.kd = None,
                Part::Wide4 => self.wide4 = None,
                Part::Wide4Hash => self.wide4_hash = None,
                Part::Wide8 => self.wide8 = None,
                Part::Wide4Naive => self.wide4_naive = None,
                Part::Wide8Sah => self.wide8_sah = None,
                Part::Levels => self.levels = None,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh2::SahBuilder;
    use crate::geometry::Triangle;
    use crate::scene::Scene;
    use glam::Vec3;

    fn scene() -> Scene {
        // A row of unit triangles: enough for a tree of several levels.
        let tris: alloc::vec::Vec<Triangle> = (0..64)
            .map(|i| {
                let x = i as f32;
                Triangle::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 0.0, 0.0), Vec3::new(x, 1.0, (i % 3) as f32))
            })
            .collect();
        Scene::new(tris).unwrap()
    }

    fn prepared(methods: &[Method]) -> PreparedScene {
        let s = scene();
        let bvh = SahBuilder::default().build(s.triangles()).unwrap();
        PreparedScene::new(&s, bvh, methods).unwrap()
    }

    #[test]
    fn a_scene_holds_exactly_the_parts_its_methods_read() {
        for m in Method::ALL {
            let p = prepared(&[m]);
            for part in Part::ALL {
                assert_eq!(p.part_bytes(part).is_some(), Part::of(m).contains(&part), "{m}: {part}");
            }
            assert!(p.method_bytes(m).is_some_and(|b| b > 0), "{m}");
            assert!(p.check_prepared(m).is_ok(), "{m}");
        }
    }

    #[test]
    fn retaining_drops_what_no_kept_method_reads() {
        let mut p = prepared(&Method::ALL);
        assert!(Part::ALL.iter().all(|&part| p.part_bytes(part).is_some()));
        let keep = [Method::Wide(WideMethod::BVH8), Method::Bvh2(Bvh2Method::Hash)];
        p.retain_parts_for(&keep);
        for part in Part::ALL {
            assert_eq!(p.part_bytes(part).is_some(), part.needed_by(&keep), "{part}");
        }
        for m in keep {
            assert!(p.check_prepared(m).is_ok(), "{m}");
        }
        assert!(p.check_prepared(Method::Kd(crate::method::KdMethod::Stack)).is_err());
    }
}
