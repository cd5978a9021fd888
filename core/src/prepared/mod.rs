//! A scene prepared for tracing: the canonical tree with the layouts and tables its methods need,
//! and nothing more, plus the conventions every backend shares about it ([`PreparedScene::canonical_ids`]).

mod enumeration;
mod frame;
pub mod normalize;
mod parts;
mod refit;

pub use frame::{FramedRays, RayCheck, FAR_FACTOR, FAR_LIMIT};
pub use parts::Part;

use crate::bvh2::traverse::TraceRoot;
use crate::bvh2::{BinaryLayout, Bvh2, LinkKind, NodeRef, SliceMemory};
use crate::geometry::Triangle;
use crate::hash::{keys_to_hash, HashCoverage, HashShape, HashStats, PerfectHash};
use crate::kd::traverse::KdRoot;
use crate::kd::{KdBuilder, KdSliceMemory, KdTree};
use crate::key::KeyWidth;
use crate::method::WideWalk;
use crate::method::{Bvh2Method, Method, StreamMethod, WideMethod, WideTreeKind};
use crate::scene::Scene;
use crate::stream::{LevelBvh, StreamScene};
use crate::wide::keyed::{keyed_nodes, WideHashedMemory};
use crate::wide::traverse::WideRoot;
use crate::wide::{WideBvh, WideSliceMemory, WideTree};
use crate::{Aabb, Error};
use alloc::vec::Vec;

/// A wide tree the scene may hold, or why building it failed.
type WideResult<const W: usize> = Result<Option<WideBvh<W>>, Error>;

/// Seconds spent deriving each part (zero without the `std` feature, which has the clock).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PrepareTimings {
    /// Both node layouts.
    pub layouts: f64,
    /// The hash over backtracking targets.
    pub hash: f64,
    /// The hash over every node.
    pub full_hash: f64,
    /// The kd-tree.
    pub kd: f64,
    /// The wide trees.
    pub wide: f64,
    /// The hash over the 4-wide tree's node keys.
    pub wide_hash: f64,
    /// The level-order tree of the stream methods.
    pub levels: f64,
}

/// A kd-tree with the triangles its leaves reference.
#[derive(Clone, Debug)]
pub struct PreparedKd {
    /// The tree.
    pub tree: KdTree,
    /// The scene's triangles, by primitive id.
    pub triangles: Vec<Triangle>,
    /// Entries of the short stack (Horn et al. 2007 use 3).
    pub short_stack: usize,
}

/// A perfect hash with its construction figures.
#[derive(Clone, Debug)]
pub struct BuiltHash {
    /// The tables.
    pub tables: PerfectHash,
    /// Sizes and counts.
    pub stats: HashStats,
}

/// A perfect hash over a wide tree's node keys ([`crate::wide::keyed`]), with the key width the
/// tree's depth needs.
#[derive(Clone, Debug)]
pub struct KeyedHash {
    /// The tables and their construction figures.
    pub hash: BuiltHash,
    /// Key and trail width.
    pub keys: KeyWidth,
}

/// A scene ready to trace: its canonical BVH2 with exactly the layouts and hash tables the
/// requested methods use, and its kd-tree if a kd method was requested. A scene traced only with
/// the stack method pays for no hash, no parent links and no kd-tree.
#[derive(Clone, Debug)]
pub struct PreparedScene {
    /// The canonical tree.
    pub bvh: Bvh2,
    /// Layout with uncle links (every method but parent/sibling).
    pub uncles: Option<BinaryLayout>,
    /// Layout with parent and sibling links.
    pub parents: Option<BinaryLayout>,
    /// Hash over backtracking targets (methods d, e).
    pub hash: Option<BuiltHash>,
    /// Hash over every node (method f).
    pub full_hash: Option<BuiltHash>,
    /// The kd-tree (kd methods), built with [`KdBuilder::default`].
    pub kd: Option<PreparedKd>,
    /// The 4-wide tree by Guthe's pull-up ([`WideMethod::BVH4`]).
    pub wide4: Option<WideBvh<4>>,
    /// The hash over the 4-wide tree's node keys ([`WideMethod::BVH4_HASH`]), or why there is
    /// none: a tree deeper than 64-bit keys allow ([`Error::TreeTooDeep`], which only that
    /// method then returns).
    pub wide4_hash: Option<Result<KeyedHash, Error>>,
    /// The 8-wide tree by the pull-up ([`WideTreeKind::Eight`]: [`WideMethod::BVH8`] and its
    /// packets and streams).
    pub wide8: Option<WideBvh<8>>,
    /// The 4-wide tree with every second level removed ([`WideMethod::BVH4_NAIVE`]).
    pub wide4_naive: Option<WideBvh<4>>,
    /// The 8-wide tree by the SAH-optimal cut ([`WideTreeKind::EightSah`]: [`WideMethod::BVH8_SAH`]
    /// and its packets and streams).
    pub wide8_sah: Option<WideBvh<8>>,
    /// The 8-wide tree laid out level by level ([`StreamMethod::Frustum8`]).
    pub levels: Option<LevelBvh>,
    /// Time spent on each part.
    pub timings: PrepareTimings,
    /// The power of two the scene was scaled by: its coordinates here are the given ones times
    /// `2^-exponent` ([`normalize`]; 0 for scenes of ordinary size). Rays go through
    /// [`PreparedScene::frame_rays`], which scales them alike.
    pub exponent: i32,
}

/// Seconds since `start` (a value this function returned), or a start mark when `None`.
#[cfg(feature = "std")]
pub(crate) fn seconds_since(start: Option<f64>) -> f64 {
    use std::time::{SystemTime, UNIX_EPOCH};
    let now = SystemTime::now().duration_since(UNIX_EPOCH).map_or(0.0, |d| d.as_secs_f64());
    start.map_or(now, |s| now - s)
}

/// Without `std` there is no clock: every timing is zero.
#[cfg(not(feature = "std"))]
pub(crate) fn seconds_since(_start: Option<f64>) -> f64 {
    0.0
}

impl PreparedScene {
    /// Derives what `methods` need from `bvh` over `scene`.
    ///
    /// Fails with [`Error::TreeMismatch`] when `bvh` does not bound `scene`'s triangles (a tree
    /// built for another scene, or for this one before its vertices moved; [`Bvh2::check_bounds`]).
    pub fn new(scene: &Scene, bvh: Bvh2, methods: &[Method]) -> Result<PreparedScene, Error> {
        bvh.check_bounds(scene.triangles())?;
        let (scaled, bvh, exponent) = normalize::normalize(scene, bvh)?;
        let scene = scaled.as_ref().unwrap_or(scene);
        let tris = scene.triangles();
        let mut timings = PrepareTimings::default();
        let t0 = seconds_since(None);
        // Exactly the parts the methods read (`Part::of`), and nothing else.
        let needs = |part: Part| part.needed_by(methods);
        let layout =
            |part: Part, links: LinkKind| needs(part).then(|| BinaryLayout::new(&bvh, tris, links)).transpose();
        let uncles = layout(Part::UncleLayout, LinkKind::Uncles)?;
        let parents = layout(Part::ParentLayout, LinkKind::ParentSibling)?;
        timings.layouts = seconds_since(Some(t0));
        let build = |coverage: HashCoverage| -> Result<BuiltHash, Error> {
            let layout = uncles.as_ref().ok_or(Error::NotPrepared { method: "hash", missing: "the uncle layout" })?;
            let keys = bvh.keys();
            let entries: Vec<(u64, NodeRef)> =
                keys_to_hash(&bvh, coverage).into_iter().map(|i| (keys[i as usize], layout.refs[i as usize])).collect();
            let (tables, stats) = PerfectHash::build(&entries, bvh.len())?;
            Ok(BuiltHash { tables, stats })
        };
        let t1 = seconds_since(None);
        let hash = needs(Part::Hash).then(|| build(HashCoverage::Backtracking)).transpose()?;
        timings.hash = seconds_since(Some(t1));
        let t2 = seconds_since(None);
        let full_hash = needs(Part::FullHash).then(|| build(HashCoverage::All)).transpose()?;
        timings.full_hash = seconds_since(Some(t2));
        let t3 = seconds_since(None);
        let kd = if needs(Part::Kd) {
            let tree = KdBuilder::default().build(tris)?;
            Some(PreparedKd { tree, triangles: tris.to_vec(), short_stack: 3 })
        } else {
            None
        };
        timings.kd = seconds_since(Some(t3));
        let t4 = seconds_since(None);
        // A generic function, since a closure cannot be generic over the width.
        fn wide<const W: usize>(needed: bool, bvh: &Bvh2, tris: &[Triangle], kind: WideTreeKind) -> WideResult<W> {
            needed.then(|| WideBvh::build(bvh, tris, kind.collapse())).transpose()
        }
        let wide4 = wide(needs(Part::Wide4), &bvh, tris, WideTreeKind::Four)?;
        let wide8 = wide(needs(Part::Wide8), &bvh, tris, WideTreeKind::Eight)?;
        let wide4_naive = wide(needs(Part::Wide4Naive), &bvh, tris, WideTreeKind::FourNaive)?;
        let wide8_sah = wide(needs(Part::Wide8Sah), &bvh, tris, WideTreeKind::EightSah)?;
        timings.wide = seconds_since(Some(t4));
        let t_hash = seconds_since(None);
        let wide4_hash = match &wide4 {
            Some(tree) if needs(Part::Wide4Hash) => Some(match keyed_nodes(tree) {
                Ok((entries, keys)) => {
                    let (tables, stats) = PerfectHash::build(&entries, tree.nodes().len())?;
                    Ok(KeyedHash { hash: BuiltHash { tables, stats }, keys })
                }
                Err(e) => Err(e),
            }),
            _ => None,
        };
        timings.wide_hash = seconds_since(Some(t_hash));
        let t5 = seconds_since(None);
        let levels = if needs(Part::Levels) {
            let bounds = bvh.nodes()[0].bounds;
            Some(match &wide8 {
                Some(w) => LevelBvh::new(w, &bounds)?,
                None => LevelBvh::new(&WideBvh::build(&bvh, tris, WideMethod::BVH8.collapse())?, &bounds)?,
            })
        } else {
            None
        };
        timings.levels = seconds_since(Some(t5));
        Ok(PreparedScene {
            bvh,
            uncles,
            parents,
            hash,
            full_hash,
            kd,
            wide4,
            wide4_hash,
            wide8,
            wide4_naive,
            wide8_sah,
            levels,
            timings,
            exponent,
        })
    }

    /// Key width the tree's depth needs.
    pub fn key_width(&self) -> KeyWidth {
        self.bvh.stats().key_width
    }

    /// The layout `method` traverses.
    pub fn layout(&self, method: Bvh2Method) -> Result<&BinaryLayout, Error> {
        let (l, what) = if method.needs_parent_links() {
            (&self.parents, "the parent/sibling layout")
        } else {
            (&self.uncles, "the uncle layout")
        };
        l.as_ref().ok_or(Error::NotPrepared { method: method.name(), missing: what })
    }

    /// The memory `method` reads: its layout and, for the hash methods, their tables.
    pub fn memory(&self, method: Bvh2Method) -> Result<SliceMemory<'_>, Error> {
        let layout = self.layout(method)?;
        let hash = if method.needs_full_hash() {
            Some(
                self.full_hash
                    .as_ref()
                    .ok_or(Error::NotPrepared { method: method.name(), missing: "the full hash" })?,
            )
        } else if method.needs_hash() {
            Some(self.hash.as_ref().ok_or(Error::NotPrepared { method: method.name(), missing: "the hash tables" })?)
        } else {
            None
        };
        Ok(SliceMemory {
            nodes: &layout.nodes,
            leaves: &layout.leaves,
            displacement: hash.map_or(&[], |h| &h.tables.displacement),
            cells: hash.map_or(&[], |h| &h.tables.cells),
            shape: hash.map_or(HashShape::default(), |h| h.tables.shape),
        })
    }

    /// The largest coordinate magnitude of the scene (its canonical tree's root box), which the
    /// per-ray slack of the BVH2 and wide methods is made from.
    pub fn scene_scale(&self) -> f32 {
        self.bvh.nodes()[0].bounds.max_abs()
    }

    /// The box of the scene's triangles in the scene's own units (the root box with the
    /// power-of-two scale undone, exactly).
    pub fn bounds(&self) -> Aabb {
        let b = self.bvh.nodes()[0].bounds;
        let up = |v: glam::Vec3| v.to_array().map(|x| normalize::scale_pow2(x, self.exponent));
        Aabb::new(up(b.min).into(), up(b.max).into())
    }

    /// Where `method` starts.
    pub fn root(&self, method: Bvh2Method) -> Result<TraceRoot, Error> {
        let scene_scale = self.scene_scale();
        Ok(TraceRoot { node: self.layout(method)?.root, scene_scale, max_steps: self.bvh.len() as u32 })
    }

    /// The kd-tree and triangles the kd methods read.
    pub fn kd_memory(&self) -> Result<KdSliceMemory<'_>, Error> {
        let kd = self.kd.as_ref().ok_or(Error::NotPrepared { method: "kd", missing: "the kd-tree" })?;
        Ok(KdSliceMemory { nodes: kd.tree.nodes(), prims: kd.tree.prims(), triangles: &kd.triangles })
    }

    /// Where the kd methods start.
    pub fn kd_root(&self) -> Result<KdRoot, Error> {
        let kd = self.kd.as_ref().ok_or(Error::NotPrepared { method: "kd", missing: "the kd-tree" })?;
        let b = kd.tree.bounds();
        Ok(KdRoot {
            lo: b.min,
            hi: b.max,
            scene_scale: b.max_abs(),
            max_steps: (kd.tree.nodes().len() + 66 * kd.tree.stats().leaves).min(u32::MAX as usize) as u32,
            short_stack: kd.short_stack,
        })
    }

    /// The wide tree `method` traverses, of its width.
    pub fn wide_tree(&self, method: WideMethod) -> Result<WideTree<'_>, Error> {
        let missing = || Error::NotPrepared { method: method.name(), missing: "its wide tree" };
        Ok(match method.tree() {
            WideTreeKind::Four => WideTree::Four(self.wide4.as_ref().ok_or_else(missing)?),
            WideTreeKind::FourNaive => WideTree::Four(self.wide4_naive.as_ref().ok_or_else(missing)?),
            WideTreeKind::Eight => WideTree::Eight(self.wide8.as_ref().ok_or_else(missing)?),
            WideTreeKind::EightSah => WideTree::Eight(self.wide8_sah.as_ref().ok_or_else(missing)?),
        })
    }

    /// The memory of a trail-walk method ([`WideWalk::Trail`]): its 4-wide tree with the hash
    /// over its keys, and the key width. [`Error::TreeTooDeep`] for a tree deeper than 64-bit keys
    /// allow.
    pub fn wide_keyed(
        &self,
        method: WideMethod,
    ) -> Result<(WideHashedMemory<'_, WideSliceMemory<'_, 4>>, KeyWidth), Error> {
        let tree = self.wide4.as_ref().filter(|_| method.walk() == WideWalk::Trail);
        let tree = tree.ok_or(Error::NotPrepared { method: method.name(), missing: "its wide tree" })?;
        let hash =
            self.wide4_hash.as_ref().ok_or(Error::NotPrepared { method: method.name(), missing: "its key hash" })?;
        let hash = hash.as_ref().map_err(Clone::clone)?;
        let t = &hash.hash.tables;
        let mem =
            WideHashedMemory { tree: tree.memory(), displacement: &t.displacement, cells: &t.cells, shape: t.shape };
        Ok((mem, hash.keys))
    }

    /// Where `method` starts, with the BVH2 methods' scene scale (so its slack is theirs).
    pub fn wide_root(&self, method: WideMethod) -> Result<WideRoot, Error> {
        let tree = self.wide_tree(method)?;
        let stats = tree.stats();
        Ok(WideRoot {
            root: tree.root(),
            scene_scale: self.scene_scale(),
            max_steps: (stats.nodes + stats.leaves).min(u32::MAX as usize) as u32,
        })
    }

    /// The wide tree the queries beyond closest and any hit walk (all hits along a ray,
    /// [`crate::all_hits`]; the nearest point, [`crate::nearest`]), with where it starts: the
    /// 8-wide tree of least node area if the scene has it (the default tracer's), else the first
    /// of the others it has. [`Error::NotPrepared`] for a scene prepared for BVH2, kd or stream
    /// methods alone.
    pub fn query_tree(&self) -> Result<(WideTree<'_>, WideRoot), Error> {
        let tree = match (&self.wide8_sah, &self.wide8, &self.wide4, &self.wide4_naive) {
            (Some(t), _, _, _) | (None, Some(t), _, _) => WideTree::Eight(t),
            (None, None, Some(t), _) | (None, None, None, Some(t)) => WideTree::Four(t),
            (None, None, None, None) => {
                return Err(Error::NotPrepared {
                    method: "all hits and nearest points",
                    missing: "a wide tree (prepare the scene for a wide method, as the default tracer is)",
                })
            }
        };
        let stats = tree.stats();
        let max_steps = (stats.nodes + stats.leaves).min(u32::MAX as usize) as u32;
        Ok((tree, WideRoot { root: tree.root(), scene_scale: self.scene_scale(), max_steps }))
    }

    /// What `method` traverses: the level-order tree with the scene box and scale.
    pub fn stream_scene(&self, method: StreamMethod) -> Result<StreamScene<'_>, Error> {
        let tree = self
            .levels
            .as_ref()
            .ok_or(Error::NotPrepared { method: method.name(), missing: "the level-order tree" })?;
        Ok(StreamScene { tree, bounds: self.bvh.nodes()[0].bounds, scene_scale: self.scene_scale() })
    }

    /// Checks that the scene holds everything `method` reads, so a backend fails before it
    /// starts (and before it times anything).
    pub fn check_prepared(&self, method: Method) -> Result<(), Error> {
        match method {
            Method::Bvh2(m) => self.memory(m).map(|_| ()),
            Method::Kd(_) => self.kd_memory().map(|_| ()),
            Method::Wide(m) if m.walk() == WideWalk::Trail => self.wide_keyed(m).map(|_| ()),
            Method::Wide(m) => self.wide_root(m).map(|_| ()),
            Method::Stream(m) => self.stream_scene(m).map(|_| ()),
        }
    }

    /// Per-ray state of `method` in bytes ([`Method::state_bytes`]) for the depth of the tree it
    /// traverses here (the binary tree's with its key width, the kd-tree's, or the wide tree's).
    pub fn state_bytes(&self, method: Method) -> usize {
        let depth = match method {
            Method::Kd(_) => self.kd.as_ref().map(|k| k.tree.stats().depth),
            Method::Wide(m) => self.wide_tree(m).ok().map(|t| t.stats().depth),
            _ => None,
        };
        method.state_bytes(depth.unwrap_or(self.bvh.stats().depth), self.key_width().bytes())
    }

    /// Bytes of the uncle layout (the BVH the hash overhead is relative to).
    pub fn bvh_bytes(&self) -> usize {
        self.uncles.as_ref().or(self.parents.as_ref()).map_or(0, BinaryLayout::bytes)
    }
}
