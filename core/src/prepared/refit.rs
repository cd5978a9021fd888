//! A prepared scene after its vertices moved: every part made again from the moved triangles in
//! linear time, with the tree's topology and every table made from it kept.

use super::{normalize, seconds_since, PrepareTimings, PreparedKd, PreparedScene};
use crate::bvh2::{BinaryLayout, LinkKind};
use crate::kd::KdBuilder;
use crate::method::WideMethod;
use crate::scene::Scene;
use crate::stream::{LevelBvh, Parallel, Serial};
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
        self.refit_with(moved, &Serial)
    }

    /// [`PreparedScene::refit`] with its passes over leaves, nodes and triangles on `par` (the CPU
    /// backend's pool: [`Bvh2::refit_with`](crate::bvh2::Bvh2::refit_with)); the result is the
    /// same bit for bit.
    pub fn refit_with(&mut self, moved: &Scene, par: &impl Parallel) -> Result<(), Error> {
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
        bvh.refit_with(tris, par)?;
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
        // The wide trees are refitted in place once nothing can fail any more (their checks
        // first), not as copies: copying the dragon's 8-wide tree (its nodes, triangles and
        // blocks) took 38 of the 53 ms its refit did. The stream methods' level tree, made
        // from the refitted 8-wide tree, can fail, so where it is kept that tree is refitted as a
        // copy first.
        let t2 = seconds_since(None);
        for check in [
            self.wide4.as_ref().map(|t| t.check_refit(&bvh, tris)),
            self.wide8.as_ref().map(|t| t.check_refit(&bvh, tris)),
            self.wide4_naive.as_ref().map(|t| t.check_refit(&bvh, tris)),
            self.wide8_sah.as_ref().map(|t| t.check_refit(&bvh, tris)),
        ]
        .into_iter()
        .flatten()
        {
            check?;
        }
        let t3 = seconds_since(None);
        let (levels, wide8) = match &self.levels {
            Some(_) => {
                let bounds = bvh.nodes()[0].bounds;
                match &self.wide8 {
                    Some(w) => {
                        let mut w = w.clone();
                        w.refit_checked(&bvh, tris, par);
                        (Some(LevelBvh::new(&w, &bounds)?), Some(w))
                    }
                    None => {
                        let w = WideBvh::build(&bvh, tris, WideMethod::BVH8.collapse())?;
                        (Some(LevelBvh::new(&w, &bounds)?), None)
                    }
                }
            }
            None => (None, None),
        };
        timings.levels = seconds_since(Some(t3));
        // Nothing fails from here on.
        let t4 = seconds_since(None);
        for tree in [&mut self.wide4, &mut self.wide4_naive].into_iter().flatten() {
            tree.refit_checked(&bvh, tris, par);
        }
        if let Some(tree) = &mut self.wide8_sah {
            tree.refit_checked(&bvh, tris, par);
        }
        match wide8 {
            Some(refitted) => self.wide8 = Some(refitted),
            None => {
                if let Some(tree) = &mut self.wide8 {
                    tree.refit_checked(&bvh, tris, par);
                }
            }
        }
        timings.wide = (t3 - t2) + seconds_since(Some(t4));
        (self.bvh, self.uncles, self.parents, self.kd, self.levels) = (bvh, uncles, parents, kd, levels);
        (self.timings, self.exponent) = (timings, exponent);
        Ok(())
    }
}
