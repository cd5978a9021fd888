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
    /// kd-tree, standard stack traversal (Horn et al. 2007, A.1).
    KdStack,
    /// kd-tree, kd-restart (A.2).
    KdRestart,
    /// kd-tree, kd-restart with push-down (A.3).
    KdPushDown,
    /// kd-tree, short-stack with push-down, restarting on underflow (A.4).
    KdShortStack,
    /// kd-tree, packetized short-stack, packets of four rays of one direction octant (A.5).
    KdPacket,
}

/// The acceleration structure a method traverses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Family {
    /// The binary BVH.
    Bvh2,
    /// The kd-tree.
    Kd,
}

impl Method {
    /// Every method.
    pub const ALL: [Method; 12] = [
        Method::Stack,
        Method::StackDisjoint,
        Method::ParentSibling,
        Method::Uncle,
        Method::Hash,
        Method::HashDisjoint,
        Method::HashResume,
        Method::KdStack,
        Method::KdRestart,
        Method::KdPushDown,
        Method::KdShortStack,
        Method::KdPacket,
    ];

    /// The BVH2 methods.
    pub const BVH2: [Method; 7] = [
        Method::Stack,
        Method::StackDisjoint,
        Method::ParentSibling,
        Method::Uncle,
        Method::Hash,
        Method::HashDisjoint,
        Method::HashResume,
    ];

    /// The kd-tree methods.
    pub const KD: [Method; 5] =
        [Method::KdStack, Method::KdRestart, Method::KdPushDown, Method::KdShortStack, Method::KdPacket];

    /// The structure the method traverses.
    pub fn family(self) -> Family {
        if Self::KD.contains(&self) {
            Family::Kd
        } else {
            Family::Bvh2
        }
    }

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
            Method::KdStack => "kd-stack",
            Method::KdRestart => "kd-restart",
            Method::KdPushDown => "kd-push-down",
            Method::KdShortStack => "kd-short-stack",
            Method::KdPacket => "kd-packet",
        }
    }

    /// The method of a command-line name.
    pub fn from_name(name: &str) -> Option<Method> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The method whose node enumeration this one must equal, closest hit and any hit alike
    /// (for kd methods the enumeration is the sequence of leaves: restarts revisit inner nodes).
    pub fn reference(self) -> Method {
        match self {
            Method::StackDisjoint | Method::HashDisjoint => Method::StackDisjoint,
            m if m.family() == Family::Kd => Method::KdStack,
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
            // Node, segment [t_min, t_max], stack pointer, (node, t_min, t_max) per level.
            Method::KdStack => addr + 8 + 4 + 12 * depth as usize,
            // Node, segment, scene exit.
            Method::KdRestart => addr + 12,
            // ... and the restart node.
            Method::KdPushDown => addr + 12 + 4,
            // ... and three stack entries with their pointer (Horn et al.'s setting).
            Method::KdShortStack => addr + 16 + 4 + 12 * 3,
            // Per ray of the packet: as short-stack, plus a live bit per entry; shared node.
            Method::KdPacket => 16 + 4 + 12 * 3 + 4,
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
