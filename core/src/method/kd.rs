use core::fmt;

/// A traversal method of the kd-tree (Horn et al. 2007, Appendix A).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum KdMethod {
    /// Standard stack traversal (A.1). Pick it for camera rays in architectural scenes on a CPU.
    Stack,
    /// kd-restart (A.2, after Foley & Sugerman 2005). Pick it for no stack at all; it descends
    /// from the root again for each leaf.
    Restart,
    /// kd-restart with push-down (A.3). Pick it over restart: it restarts lower in the tree.
    PushDown,
    /// Short-stack with push-down, restarting on underflow (A.4). Pick it for a stackless kd walk
    /// with a few registers to spare: restarts become rare.
    ShortStack,
    /// Packetized short-stack, packets of four rays of one direction octant (A.5). Pick it for
    /// coherent rays on the kd-tree.
    Packet,
}

impl KdMethod {
    /// Every kd method.
    pub const ALL: [KdMethod; 5] =
        [KdMethod::Stack, KdMethod::Restart, KdMethod::PushDown, KdMethod::ShortStack, KdMethod::Packet];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            KdMethod::Stack => "kd-stack",
            KdMethod::Restart => "kd-restart",
            KdMethod::PushDown => "kd-push-down",
            KdMethod::ShortStack => "kd-short-stack",
            KdMethod::Packet => "kd-packet",
        }
    }

    /// Per-ray state in bytes for a tree of `depth` levels
    /// (see [`Method::state_bytes`](super::Method::state_bytes)).
    pub fn state_bytes(self, depth: u32) -> usize {
        let addr = 4;
        match self {
            // Node, segment [t_min, t_max], stack pointer, (node, t_min, t_max) per level.
            KdMethod::Stack => addr + 8 + 4 + 12 * depth as usize,
            // Node, segment, scene exit.
            KdMethod::Restart => addr + 12,
            // ... and the restart node.
            KdMethod::PushDown => addr + 12 + 4,
            // ... and three stack entries with their pointer (Horn et al.'s setting).
            KdMethod::ShortStack => addr + 16 + 4 + 12 * 3,
            // Per ray of the packet: as short-stack, plus a live bit per entry; shared node.
            KdMethod::Packet => 16 + 4 + 12 * 3 + 4,
        }
    }
}

impl fmt::Display for KdMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
