use core::fmt;

/// A traversal method of the binary BVH (the letters are those of the foundation issue).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Bvh2Method {
    /// (a) Stack-based, "while-while" order, closer child first (Aila & Laine 2009).
    /// Pick it for the binary tree on a CPU: the fastest BVH2 walk there, and every BVH2 method's
    /// reference.
    Stack,
    /// (a') The stack method pruning postponed nodes by the disjoint t-interval rule: the
    /// reference that method (e) must enumerate identically. Pick it only to check (e).
    StackDisjoint,
    /// (b) Stackless with parent and sibling links and a bit trail (Áfra et al. 2014).
    /// Pick it where per-ray memory is scarcest and no table fits: backtracking climbs the tree.
    ParentSibling,
    /// (c) Iterative backtracking over uncle and grand-uncle links, with the register (Binder &
    /// Keller 2016, Sec. 2.2). Pick it for a stackless walk without hash tables.
    Uncle,
    /// (d) Constant-time backtracking: register, uncle links, perfect hash (Binder & Keller
    /// 2016, Algorithm 1). Pick it for GPUs and hardware where a per-ray stack is costly.
    Hash,
    /// (e) As (d), with the disjoint t-interval mask (Binder & Keller 2016, Sec. 2.3). Pick it
    /// over (d) for closest hits in trees whose boxes overlap much.
    HashDisjoint,
    /// (f) As (d), pausing after every hit and resuming from the node key (Binder & Keller 2016,
    /// Sec. 2.4). Pick it where a walk must stop at each hit and go on later (hit filters).
    HashResume,
}

impl Bvh2Method {
    /// Every BVH2 method.
    pub const ALL: [Bvh2Method; 7] = [
        Bvh2Method::Stack,
        Bvh2Method::StackDisjoint,
        Bvh2Method::ParentSibling,
        Bvh2Method::Uncle,
        Bvh2Method::Hash,
        Bvh2Method::HashDisjoint,
        Bvh2Method::HashResume,
    ];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Bvh2Method::Stack => "stack",
            Bvh2Method::StackDisjoint => "stack-disjoint",
            Bvh2Method::ParentSibling => "parent-sibling",
            Bvh2Method::Uncle => "uncle",
            Bvh2Method::Hash => "hash",
            Bvh2Method::HashDisjoint => "hash-disjoint",
            Bvh2Method::HashResume => "hash-resume",
        }
    }

    /// The method whose node enumeration this one must equal, closest hit and any hit alike.
    pub fn reference(self) -> Bvh2Method {
        match self {
            Bvh2Method::StackDisjoint | Bvh2Method::HashDisjoint => Bvh2Method::StackDisjoint,
            _ => Bvh2Method::Stack,
        }
    }

    /// Per-ray state in bytes for a tree of `depth` levels and keys of `key_bytes`
    /// (see [`Method::state_bytes`](super::Method::state_bytes)).
    pub fn state_bytes(self, depth: u32, key_bytes: usize) -> usize {
        let addr = 4;
        match self {
            // Node address, stack pointer, one entry per level (the deepest possible stack).
            Bvh2Method::Stack => addr + 4 + 4 * depth as usize,
            // ... and one disjoint flag per entry, packed in a word of the key width.
            Bvh2Method::StackDisjoint => addr + 4 + 4 * depth as usize + key_bytes,
            // Node address and bit trail.
            Bvh2Method::ParentSibling => addr + key_bytes,
            // Node address, bit trail, register.
            Bvh2Method::Uncle => addr + key_bytes + 4,
            // Node address, key, bit trail, register.
            Bvh2Method::Hash | Bvh2Method::HashResume => addr + 2 * key_bytes + 4,
            // ... and the disjoint-interval trail.
            Bvh2Method::HashDisjoint => addr + 3 * key_bytes + 4,
        }
    }

    /// Whether the method needs the perfect hash over backtracking targets.
    pub fn needs_hash(self) -> bool {
        matches!(self, Bvh2Method::Hash | Bvh2Method::HashDisjoint)
    }

    /// Whether the method needs the hash over every node (resuming from any key).
    pub fn needs_full_hash(self) -> bool {
        self == Bvh2Method::HashResume
    }

    /// Whether the method needs the parent/sibling layout rather than the uncle layout.
    pub fn needs_parent_links(self) -> bool {
        self == Bvh2Method::ParentSibling
    }
}

impl fmt::Display for Bvh2Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
