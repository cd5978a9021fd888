use crate::Error;
use core::fmt;

/// A traversal method of a wide BVH, collapsed from the canonical BVH2 (Guthe 2014): a tree
/// ([`WideTreeKind`]) and a way to walk it ([`WideWalk`]).
///
/// Each visits a node's children at once: their boxes are tested together (independent
/// instruction sequences, the paper's point), closest-hit queries order the hit children by entry
/// distance with a sorting network, and any-hit queries push them unsorted (Sec. 4.2). Not every
/// pair is a method: [`WideMethod::ALL`] lists those that are, [`WideMethod::new`] refuses the
/// others.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct WideMethod {
    tree: WideTreeKind,
    walk: WideWalk,
}

/// How a wide tree is walked.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WideWalk {
    /// One ray at a time with a stack of (child, entry distance) (Guthe 2014, Sec. 4.2).
    Stack,
    /// Packets of rays of one octant ([`crate::wide::packet`]): one node fetch, child order and
    /// stack per packet, each ray's own box tests and answer. Beyond Guthe's paper.
    Packet,
    /// Batches of thousands of consecutive rays ([`crate::wide::ray_stream`]), a node fetched
    /// once for every ray of the batch that reaches it and a list of rays kept per hit child, each
    /// ray's own box tests, answer and events (Barringer & Akenine-Möller 2014's dynamic ray
    /// streams; not Garanzha & Loop's `stream` method, [`crate::method::StreamMethod`]).
    RayLists,
    /// One ray at a time without a stack ([`crate::wide::trail`]): Binder & Keller's node keys,
    /// bit trail and perfect hash at `log2 W` key bits per level, a backtrack being one hash
    /// lookup and the parent's box tests again. Beyond both papers.
    Trail,
}

impl WideWalk {
    /// Whether several rays share one walk of the tree (packets, ray lists): such a method's
    /// events for one ray depend on the rays it is traced with.
    pub fn shares_walks(self) -> bool {
        matches!(self, WideWalk::Packet | WideWalk::RayLists)
    }
}

impl WideMethod {
    /// Four children per node, by Guthe's pull-up (Guthe 2014, Sec. 4.1). Pick it for 4-wide
    /// vector units; on 8-wide ones [`WideMethod::BVH8`] is faster.
    pub const BVH4: WideMethod = WideMethod { tree: WideTreeKind::Four, walk: WideWalk::Stack };
    /// Eight children per node, by the same pull-up (the width of Garanzha & Loop's tree). Pick it
    /// for any-hit rays one at a time: the largest child comes first.
    pub const BVH8: WideMethod = WideMethod { tree: WideTreeKind::Eight, walk: WideWalk::Stack };
    /// Four children per node by removing every second level of the binary tree: the naive
    /// collapse the pull-up is measured against (Guthe 2014, Sec. 4.1). Pick it only to measure.
    pub const BVH4_NAIVE: WideMethod = WideMethod { tree: WideTreeKind::FourNaive, walk: WideWalk::Stack };
    /// Eight children per node, by the cut of least total node area ([`Collapse::Optimal`]):
    /// fewer nodes per closest-hit ray than the pull-up, more per shadow ray (Ylitie, Karras &
    /// Laine 2017, the collapse). Pick it for closest-hit rays one at a time or in no order.
    pub const BVH8_SAH: WideMethod = WideMethod { tree: WideTreeKind::EightSah, walk: WideWalk::Stack };
    /// [`WideMethod::BVH8`]'s tree walked by packets ([`WideWalk::Packet`]). Pick it for coherent
    /// rays (camera rays, shadow rays to one light).
    pub const BVH8_PACKET: WideMethod = WideMethod { tree: WideTreeKind::Eight, walk: WideWalk::Packet };
    /// [`WideMethod::BVH8`]'s tree walked by ray lists ([`WideWalk::RayLists`]), no hand-over to
    /// single rays. Pick it for large batches of incoherent closest-hit rays (diffuse bounces);
    /// any-hit rays gain nothing from it.
    pub const BVH8_LISTS: WideMethod = WideMethod { tree: WideTreeKind::Eight, walk: WideWalk::RayLists };
    /// [`WideMethod::BVH4`]'s tree and visiting order without a stack ([`WideWalk::Trail`]). Pick
    /// it for a wide tree without a per-ray stack (GPUs, hardware).
    pub const BVH4_HASH: WideMethod = WideMethod { tree: WideTreeKind::Four, walk: WideWalk::Trail };
    /// [`WideMethod::BVH8_SAH`]'s tree walked by packets: the cut of least node area serves
    /// closest-hit packets better and shadow-ray packets worse. Pick it for coherent closest-hit
    /// rays (camera rays).
    pub const BVH8_SAH_PACKET: WideMethod = WideMethod { tree: WideTreeKind::EightSah, walk: WideWalk::Packet };
    /// [`WideMethod::BVH8_SAH`]'s tree walked by ray lists. Pick it for large batches of
    /// incoherent closest-hit rays.
    pub const BVH8_SAH_LISTS: WideMethod = WideMethod { tree: WideTreeKind::EightSah, walk: WideWalk::RayLists };
}

/// The wide trees a scene may hold: methods that name the same one share it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WideTreeKind {
    /// Four children per node by the pull-up.
    Four,
    /// Four children per node with every second level removed.
    FourNaive,
    /// Eight children per node by the pull-up.
    Eight,
    /// Eight children per node by the SAH-optimal cut.
    EightSah,
}

impl WideTreeKind {
    /// Children per node.
    pub fn width(self) -> usize {
        match self {
            WideTreeKind::Four | WideTreeKind::FourNaive => 4,
            WideTreeKind::Eight | WideTreeKind::EightSah => 8,
        }
    }

    /// How the tree is collapsed from the binary one.
    pub fn collapse(self) -> Collapse {
        match self {
            WideTreeKind::Four | WideTreeKind::Eight => Collapse::PullUp,
            WideTreeKind::FourNaive => Collapse::EverySecondLevel,
            WideTreeKind::EightSah => Collapse::Optimal,
        }
    }
}

/// How a wide tree is collapsed from the binary one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Collapse {
    /// Guthe's pull-up: the largest child first, with the paper's rules near the leaves.
    PullUp,
    /// Every second level removed.
    EverySecondLevel,
    /// The cut of least total node area under the surface-area heuristic, by dynamic
    /// programming (Ylitie et al. 2017's collapse, binary leaves kept whole).
    Optimal,
}

impl WideMethod {
    /// Every wide method, in the order reports list them.
    pub const ALL: [WideMethod; 9] = [
        WideMethod::BVH4,
        WideMethod::BVH8,
        WideMethod::BVH4_NAIVE,
        WideMethod::BVH8_SAH,
        WideMethod::BVH8_PACKET,
        WideMethod::BVH8_LISTS,
        WideMethod::BVH4_HASH,
        WideMethod::BVH8_SAH_PACKET,
        WideMethod::BVH8_SAH_LISTS,
    ];

    /// Command-line names of [`WideMethod::ALL`], in order.
    const NAMES: [&'static str; 9] = [
        "bvh4",
        "bvh8",
        "bvh4-naive",
        "bvh8-sah",
        "bvh8-packet",
        "bvh8-lists",
        "bvh4-hash",
        "bvh8-sah-packet",
        "bvh8-sah-lists",
    ];

    /// Former command-line names still accepted by [`WideMethod::from_name`], with the method each
    /// now names: the ray-list walk was called `stream`, a word now kept for Garanzha & Loop's
    /// method. Accepted for one release.
    pub const OLD_NAMES: [(&'static str, WideMethod); 2] =
        [("bvh8-stream", WideMethod::BVH8_LISTS), ("bvh8-sah-stream", WideMethod::BVH8_SAH_LISTS)];

    /// The method walking `tree` by `walk`, or [`Error::Unsupported`] for a pair that is none of
    /// [`WideMethod::ALL`] (a packet or ray-list walk needs an 8-wide tree, the trail the
    /// pull-up's 4-wide one).
    pub fn new(tree: WideTreeKind, walk: WideWalk) -> Result<WideMethod, Error> {
        let m = WideMethod { tree, walk };
        if WideMethod::ALL.contains(&m) {
            Ok(m)
        } else {
            Err(Error::Unsupported { method: "this wide tree and walk", by: "any wide method" })
        }
    }

    /// Position in [`WideMethod::ALL`].
    fn index(self) -> usize {
        WideMethod::ALL.iter().position(|&m| m == self).unwrap_or(WideMethod::ALL.len())
    }

    /// Command-line name.
    pub fn name(self) -> &'static str {
        WideMethod::NAMES.get(self.index()).copied().unwrap_or("wide")
    }

    /// The method of a command-line name, or of a former one ([`WideMethod::OLD_NAMES`]).
    pub fn from_name(name: &str) -> Option<WideMethod> {
        let current = WideMethod::ALL.into_iter().find(|m| m.name() == name);
        current.or_else(|| WideMethod::OLD_NAMES.iter().find(|(old, _)| *old == name).map(|&(_, m)| m))
    }

    /// The tree the method walks.
    pub fn tree(self) -> WideTreeKind {
        self.tree
    }

    /// How the method walks its tree.
    pub fn walk(self) -> WideWalk {
        self.walk
    }

    /// Children per node.
    pub fn width(self) -> usize {
        self.tree.width()
    }

    /// How the method's tree is collapsed.
    pub fn collapse(self) -> Collapse {
        self.tree().collapse()
    }

    /// Per-ray state in bytes for a wide tree of `depth` levels: node address, current entry
    /// distance, stack pointer, and `width - 1` entries of (node, entry distance) per level. A
    /// packet's node, mask and stack (entries of node, ray mask and key) are shared by its
    /// [`WIDE_PACKET`](crate::wide::WIDE_PACKET) rays; each ray adds its box interval, and
    /// the single-ray state it needs when the packet hands it a subtree. A ray-list walk's stack holds
    /// at most `width - 1` entries per level (node and list bounds), and each ray is in at most
    /// that many lists (its index and entry distance), with its slab constants, interval and
    /// answer besides (the batch shares nothing else). The trail walk keeps
    /// the node address, its key, its trail and a register (a parent node), whatever the depth.
    pub fn state_bytes(self, depth: u32) -> usize {
        match self.walk {
            WideWalk::Trail => {
                let key = match crate::wide::keyed::wide_key_width::<4>(depth) {
                    Some(crate::key::KeyWidth::W32) => 4,
                    _ => 8,
                };
                4 + 2 * key + 4
            }
            WideWalk::RayLists => {
                let entries = (self.width() - 1) * depth as usize;
                let shared = 8 + 16 * entries;
                let own = core::mem::size_of::<crate::intersect::SlabRay>() + 8 + 16;
                8 * entries + own + shared.div_ceil(crate::wide::STREAM_RAYS)
            }
            WideWalk::Packet => {
                let rays = crate::wide::WIDE_PACKET;
                let shared = 8 + 8 + 4 + 16 * (self.width() - 1) * depth as usize;
                8 + shared.div_ceil(rays) + self.single_ray_bytes(depth)
            }
            WideWalk::Stack => self.single_ray_bytes(depth),
        }
    }

    /// A stack traversal's state for one ray over `depth` levels.
    fn single_ray_bytes(self, depth: u32) -> usize {
        4 + 4 + 4 + 8 * (self.width() - 1) * depth as usize
    }
}

/// Methods order as [`WideMethod::ALL`] lists them.
impl PartialOrd for WideMethod {
    fn partial_cmp(&self, other: &Self) -> Option<core::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for WideMethod {
    fn cmp(&self, other: &Self) -> core::cmp::Ordering {
        self.index().cmp(&other.index())
    }
}

impl fmt::Display for WideMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
