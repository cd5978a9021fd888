use core::fmt;

/// A BVH2 traversal method (the letters are those of the foundation issue).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Method {
    /// (a) Stack-based, "while-while" order, closer child first (Aila & Laine 2009).
    Stack,
    /// (a') The stack method pruning postponed nodes by the disjoint t-interval rule: the
    /// reference that method (e) must enumerate identically.
    StackDisjoint,
    /// (b) Stackless with parent and sibling links and a bit trail (Áfra et al. 2014).
    ParentSibling,
    /// (c) Iterative backtracking over uncle and grand-uncle links, with the register.
    Uncle,
    /// (d) Constant-time backtracking: register, uncle links, perfect hash (Algorithm 1).
    Hash,
    /// (e) As (d), with the disjoint t-interval mask (Sec. 2.3).
    HashDisjoint,
    /// (f) As (d), pausing after every hit and resuming from the node key (Sec. 2.4).
    HashResume,
}

impl Method {
    /// Every method.
    pub const ALL: [Method; 7] = [
        Method::Stack,
        Method::StackDisjoint,
        Method::ParentSibling,
        Method::Uncle,
        Method::Hash,
        Method::HashDisjoint,
        Method::HashResume,
    ];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Method::Stack => "stack",
            Method::StackDisjoint => "stack-disjoint",
            Method::ParentSibling => "parent-sibling",
            Method::Uncle => "uncle",
            Method::Hash => "hash",
            Method::HashDisjoint => "hash-disjoint",
            Method::HashResume => "hash-resume",
        }
    }

    /// The method of a command-line name.
    pub fn from_name(name: &str) -> Option<Method> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The method whose node enumeration this one must equal, closest hit and any hit alike.
    pub fn reference(self) -> Method {
        match self {
            Method::StackDisjoint | Method::HashDisjoint => Method::StackDisjoint,
            _ => Method::Stack,
        }
    }

    /// Per-ray traversal state in bytes, beyond the ray and its answer: the registers the paper
    /// names, for a tree of the given depth and key width in bytes, as a hardware unit or a
    /// shader sized for this tree would hold them. (The Rust state types are larger: the stack
    /// is fixed at 64 entries so one type serves every tree.)
    pub fn state_bytes(self, depth: u32, key_bytes: usize) -> usize {
        let addr = 4;
        match self {
            // Node address, stack pointer, one entry per level (the deepest possible stack).
            Method::Stack => addr + 4 + 4 * depth as usize,
            // ... and one disjoint flag per entry, packed in a word of the key width.
            Method::StackDisjoint => addr + 4 + 4 * depth as usize + key_bytes,
            // Node address and bit trail.
            Method::ParentSibling => addr + key_bytes,
            // Node address, bit trail, register.
            Method::Uncle => addr + key_bytes + 4,
            // Node address, key, bit trail, register.
            Method::Hash | Method::HashResume => addr + 2 * key_bytes + 4,
            // ... and the disjoint-interval trail.
            Method::HashDisjoint => addr + 3 * key_bytes + 4,
        }
    }

    /// Whether the method needs the perfect hash over backtracking targets.
    pub fn needs_hash(self) -> bool {
        matches!(self, Method::Hash | Method::HashDisjoint)
    }

    /// Whether the method needs the hash over every node (resuming from any key).
    pub fn needs_full_hash(self) -> bool {
        self == Method::HashResume
    }

    /// Whether the method needs the parent/sibling layout rather than the uncle layout.
    pub fn needs_parent_links(self) -> bool {
        self == Method::ParentSibling
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What a ray asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Query {
    /// The closest hit (ties to the smaller primitive id).
    Closest,
    /// Whether anything is hit (occlusion); the hit reported is the first one found.
    Any,
}

impl Query {
    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Query::Closest => "closest",
            Query::Any => "any",
        }
    }
}
