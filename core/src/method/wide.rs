use core::fmt;

/// A traversal method of a wide BVH, collapsed from the canonical BVH2 (Guthe 2014).
///
/// Each visits a node's children at once: their boxes are tested together (independent
/// instruction sequences, the paper's point), closest-hit queries order the hit children by entry
/// distance with a sorting network, and any-hit queries push them unsorted (Sec. 4.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum WideMethod {
    /// Four children per node, by Guthe's pull-up (Guthe 2014, Sec. 4.1). Pick it for 4-wide
    /// vector units; on 8-wide ones [`WideMethod::Bvh8`] is faster.
    Bvh4,
    /// Eight children per node, by the same pull-up (the width of Garanzha & Loop's tree). Pick it
    /// for any-hit rays one at a time: the largest child comes first.
    Bvh8,
    /// Four children per node by removing every second level of the binary tree: the naive
    /// collapse the pull-up is measured against (Guthe 2014, Sec. 4.1). Pick it only to measure.
    Bvh4Naive,
    /// Eight children per node, by the cut of least total node area ([`Collapse::Optimal`]):
    /// fewer nodes per closest-hit ray than the pull-up, more per shadow ray (Ylitie, Karras &
    /// Laine 2017, the collapse). Pick it for closest-hit rays one at a time or in no order.
    Bvh8Sah,
    /// [`WideMethod::Bvh8`]'s tree walked by packets of rays of one octant
    /// ([`crate::wide::packet`]): one node fetch, child order and stack per packet, each ray's own
    /// box tests and answer. Beyond Guthe's paper. Pick it for coherent rays (camera rays, shadow
    /// rays to one light).
    Bvh8Packet,
    /// [`WideMethod::Bvh8`]'s tree walked by streams of thousands of consecutive rays
    /// ([`crate::wide::ray_stream`]): a node fetched once for every ray of the stream that reaches
    /// it, each ray's own box tests, answer and events, no hand-over to single rays. Beyond both
    /// papers (Barringer & Akenine-Möller 2014's dynamic ray streams). Pick it for large batches
    /// of incoherent closest-hit rays (diffuse bounces); any-hit rays gain nothing from it.
    Bvh8Stream,
    /// [`WideMethod::Bvh4`]'s tree and visiting order without a stack ([`crate::wide::trail`]):
    /// Binder & Keller's node keys, bit trail and perfect hash at two key bits per level, a
    /// backtrack being one hash lookup and the parent's box tests again. Beyond both papers. Pick
    /// it for a wide tree without a per-ray stack (GPUs, hardware).
    Bvh4Hash,
    /// [`WideMethod::Bvh8Sah`]'s tree walked by packets, as [`WideMethod::Bvh8Packet`] walks the
    /// pull-up's: the cut of least node area serves closest-hit packets better and shadow-ray
    /// packets worse. Pick it for coherent closest-hit rays (camera rays).
    Bvh8SahPacket,
    /// [`WideMethod::Bvh8Sah`]'s tree walked by ray streams, as [`WideMethod::Bvh8Stream`] walks
    /// the pull-up's. Pick it for large batches of incoherent closest-hit rays.
    Bvh8SahStream,
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
    /// Every wide method.
    pub const ALL: [WideMethod; 9] = [
        WideMethod::Bvh4,
        WideMethod::Bvh8,
        WideMethod::Bvh4Naive,
        WideMethod::Bvh8Sah,
        WideMethod::Bvh8Packet,
        WideMethod::Bvh8Stream,
        WideMethod::Bvh4Hash,
        WideMethod::Bvh8SahPacket,
        WideMethod::Bvh8SahStream,
    ];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            WideMethod::Bvh4 => "bvh4",
            WideMethod::Bvh8 => "bvh8",
            WideMethod::Bvh4Naive => "bvh4-naive",
            WideMethod::Bvh8Sah => "bvh8-sah",
            WideMethod::Bvh8Packet => "bvh8-packet",
            WideMethod::Bvh8Stream => "bvh8-stream",
            WideMethod::Bvh4Hash => "bvh4-hash",
            WideMethod::Bvh8SahPacket => "bvh8-sah-packet",
            WideMethod::Bvh8SahStream => "bvh8-sah-stream",
        }
    }

    /// The tree the method walks.
    pub fn tree(self) -> WideTreeKind {
        match self {
            WideMethod::Bvh4 | WideMethod::Bvh4Hash => WideTreeKind::Four,
            WideMethod::Bvh4Naive => WideTreeKind::FourNaive,
            WideMethod::Bvh8 | WideMethod::Bvh8Packet | WideMethod::Bvh8Stream => WideTreeKind::Eight,
            WideMethod::Bvh8Sah | WideMethod::Bvh8SahPacket | WideMethod::Bvh8SahStream => WideTreeKind::EightSah,
        }
    }

    /// Children per node.
    pub fn width(self) -> usize {
        self.tree().width()
    }

    /// How the method's tree is collapsed.
    pub fn collapse(self) -> Collapse {
        self.tree().collapse()
    }

    /// Whether rays are traced in packets ([`crate::wide::packet`]) rather than one at a time.
    pub fn packets(self) -> bool {
        matches!(self, WideMethod::Bvh8Packet | WideMethod::Bvh8SahPacket)
    }

    /// Whether rays are traced in streams ([`crate::wide::ray_stream`]) rather than one at a time.
    pub fn streams(self) -> bool {
        matches!(self, WideMethod::Bvh8Stream | WideMethod::Bvh8SahStream)
    }

    /// Whether several rays share one walk of the tree (packets or streams): such a method's
    /// events for one ray depend on the rays it is traced with.
    pub fn shares_walks(self) -> bool {
        self.packets() || self.streams()
    }

    /// Whether the method walks the tree without a stack, by node keys and a perfect hash
    /// ([`crate::wide::trail`]).
    pub fn keyed(self) -> bool {
        self == WideMethod::Bvh4Hash
    }

    /// Per-ray state in bytes for a wide tree of `depth` levels: node address, current entry
    /// distance, stack pointer, and `width - 1` entries of (node, entry distance) per level. A
    /// packet's node, mask and stack (entries of node, ray mask and key) are shared by its
    /// [`WIDE_PACKET`](crate::wide::WIDE_PACKET) rays; each ray adds its box interval, and
    /// the single-ray state it needs when the packet hands it a subtree. A stream's stack holds
    /// at most `width - 1` entries per level (node and list bounds), and each ray is in at most
    /// that many lists (its index and entry distance), with its slab constants, interval and
    /// answer besides (the stream shares nothing else). The keyed method keeps
    /// the node address, its key, its trail and a register (a parent node), whatever the depth.
    pub fn state_bytes(self, depth: u32) -> usize {
        if self.keyed() {
            let key = match crate::wide::keyed::wide_key_width::<4>(depth) {
                Some(crate::key::KeyWidth::W32) => 4,
                _ => 8,
            };
            4 + 2 * key + 4
        } else if self.streams() {
            let entries = (self.width() - 1) * depth as usize;
            let shared = 8 + 16 * entries;
            let own = core::mem::size_of::<crate::intersect::SlabRay>() + 8 + 16;
            8 * entries + own + shared.div_ceil(crate::wide::STREAM_RAYS)
        } else if self.packets() {
            let rays = crate::wide::WIDE_PACKET;
            let shared = 8 + 8 + 4 + 16 * (self.width() - 1) * depth as usize;
            8 + shared.div_ceil(rays) + self.single_ray_bytes(depth)
        } else {
            self.single_ray_bytes(depth)
        }
    }

    /// A stack traversal's state for one ray over `depth` levels.
    fn single_ray_bytes(self, depth: u32) -> usize {
        4 + 4 + 4 + 8 * (self.width() - 1) * depth as usize
    }
}

impl fmt::Display for WideMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
