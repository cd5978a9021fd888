//! A prepared scene after its vertices moved: every part made again from the moved triangles in
//! linear time, with the tree's topology and every table made from it kept.

use super::{normalize, seconds_since, PrepareTimings, PreparedKd, PreparedScene};
use crate::bvh2::{BinaryLayout, LinkKind};
use crate::kd::KdBuilder;
use crate::method::WideMethod;
use crate::scene::Scene;
use crate::stream::LevelBvh;
use crate::wide::WideBvh;
use crate::Error;

impl PreparedScene {
    /// Moves the scene to `moved`: the same number of triangles (by primitive id) at new
    /// positions, as an animation or a simulation step gives them. What is refitted, and why the
    /// rest stays valid:
    /// - the canonical tree's boxes, bottom-up ([`crate::bvh2::Bvh2::refit`]);
    /// - the wide trees' child boxes and triangles ([`WideBvh::refit`]), their collapse and slot
    ///   order kept;
    /// - the binary layouts, laid out again (their node addresses and links come from the
    ///   topology, so they are the same);
    /// - the kd-tree, built again (a kd-tree's split planes are positions, not a topology over
    ///   the triangles, so it cannot be refitted), and the stream methods' level-order tree, made
    ///   again from the refitted 8-wide tree;
    /// - kept as they are: node keys, bit trails and the perfect hashes over them (BVH2 and
    ///   4-wide), which depend on the topology alone.
    ///
    /// Hits afterwards are bit for bit those of a scene prepared afresh from `moved` (the
    /// conformance suite's refit case checks every method on every backend); node visits follow
    /// the kept topology, whose quality drifts as the triangles move away from where it was built
    /// for: rebuild ([`PreparedScene::new`]) when tracing slows. The scale of
    /// [`PreparedScene::exponent`] is chosen again for the moved scene.
    ///
    /// [`Error::TreeMismatch`] when `moved` has another triangle count; the scene is then
    /// unchanged. [`PreparedScene::timings`] afterwards holds the refit's times.
    pub fn refit(&mut self, moved: &Scene) -> Result<(), Error> {
        if moved.triangles().len() != self.bvh.prim_count() {
            return Err(Error::TreeMismatch {
                node: 0,
                why: "refit: the new triangle count differs from the tree's primitive count",
            });
        }
        let (scaled, exponent) = normalize::scaled_scene(moved)?;
        let tris = scaled.as_ref().unwrap_or(moved).triangles();
        let mut timings = PrepareTimings::default();
        // Everything fallible that allocates is made before anything is replaced, so that an
        // error leaves the scene as it was.
        let t0 = seconds_since(None);
        let mut bvh = self.bvh.clone();
        bvh.refit(tris)?;
        let layout = |old: &Option<BinaryLayout>, links| old.as_ref().map(|_| BinaryLayout::new(&bvh, tris, links));
        let uncles = layout(&self.uncles, LinkKind::Uncles).transpose()?;
        let parents = layout(&self.parents, LinkKind::ParentSibling).transpose()?;
        timings.layouts = seconds_since(Some(t0));
        let t1 = seconds_since(None);
        let kd = match &self.kd {
            Some(old) => Some(PreparedKd {
                tree: KdBuilder::default().build(tris)?,
                triangles: tris.to_vec(),
                short_stack: old.short_stack,
            }),
            None => None,
        };
        timings.kd = seconds_since(Some(t1));
        let t2 = seconds_since(None);
        fn refit<const W: usize>(
            tree: &Option<WideBvh<W>>,
            bvh: &crate::bvh2::Bvh2,
            tris: &[crate::geometry::Triangle],
        ) -> Result<Option<WideBvh<W>>, Error> {
            let mut tree = tree.clone();
            if let Some(t) = &mut tree {
                t.refit(bvh, tris)?;
            }
            Ok(tree)
        }
        let wide4 = refit(&self.wide4, &bvh, tris)?;
        let wide8 = refit(&self.wide8, &bvh, tris)?;
        let wide4_naive = refit(&self.wide4_naive, &bvh, tris)?;
        let wide8_sah = refit(&self.wide8_sah, &bvh, tris)?;
        timings.wide = seconds_since(Some(t2));
        let t3 = seconds_since(None);
        let levels = match &self.levels {
            Some(_) => {
                let bounds = bvh.nodes()[0].bounds;
                Some(match &wide8 {
                    Some(w) => LevelBvh::new(w, &bounds)?,
                    None => LevelBvh::new(&WideBvh::build(&bvh, tris, WideMethod::BVH8.collapse())?, &bounds)?,
                })
            }
            None => None,
        };
        timings.levels = seconds_since(Some(t3));
        (self.bvh, self.uncles, self.parents, self.kd) = (bvh, uncles, parents, kd);
        (self.wide4, self.wide8, self.wide4_naive, self.wide8_sah, self.levels) =
            (wide4, wide8, wide4_naive, wide8_sah, levels);
        (self.timings, self.exponent) = (timings, exponent);
        Ok(())
    }
}
