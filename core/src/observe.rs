//! Observers: what a traversal reports as it runs (docs/ARCHITECTURE.md, "Traversal: a state machine plus an observer").
//!
//! Every method calls the same hooks at the same points. [`NoObserver`] sets
//! [`Observer::ENABLED`] to `false`; methods guard any work done only for an observer behind that
//! constant, so the default compiles away. Recording an enumeration ([`Recorder`]) and counting
//! work ([`Counters`]) are observers.

use crate::bvh2::NodeRef;

/// Where the register a constant-time backtracking step used got its reference from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RegisterSource {
    /// Stored when the node was postponed.
    Postponed,
    /// Loaded from an uncle link.
    Uncle,
    /// Loaded from a grand-uncle link.
    GrandUncle,
    /// Loaded from a leaf's grand-grand-uncle link.
    GrandGrandUncle,
}

/// How one backtracking step found the next node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Backtrack {
    /// Popped from a stack.
    StackPop,
    /// The most-recently-postponed-node register.
    Register(RegisterSource),
    /// The perfect hash; `direct` when the displacement entry held the address itself.
    Hash {
        /// Served by the displacement table alone.
        direct: bool,
    },
    /// Iterating over parent and sibling links, or uncle links.
    Iterative,
    /// Descending again from the root or a pushed-down node (kd-restart).
    Restart,
}

/// Receives traversal events. Every hook defaults to doing nothing.
pub trait Observer {
    /// `false` lets methods skip work done only to feed the observer.
    const ENABLED: bool = true;
    /// A node (internal or leaf) was loaded and processed: one entry of the enumeration.
    #[inline(always)]
    fn node(&mut self, _node: NodeRef) {}
    /// A ray/primitive test was made.
    #[inline(always)]
    fn primitive(&mut self, _prim: u32) {}
    /// A hit was accepted (closer than any before, or the any-hit answer).
    #[inline(always)]
    fn hit(&mut self, _prim: u32, _t: f32) {}
    /// One backtracking step climbed `levels` levels and found the next node `via`.
    #[inline(always)]
    fn backtrack(&mut self, _levels: u32, _via: Backtrack) {}
    /// A node record was read to follow a link while backtracking, without visiting the node.
    #[inline(always)]
    fn link_read(&mut self, _node: NodeRef) {}
}

/// The observer that observes nothing and costs nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoObserver;

impl Observer for NoObserver {
    const ENABLED: bool = false;
}

/// Work counters, summed over rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Rays traced.
    pub rays: u64,
    /// Internal nodes visited.
    pub internal_nodes: u64,
    /// Leaves visited.
    pub leaves: u64,
    /// Ray/primitive tests.
    pub primitive_tests: u64,
    /// Backtracking steps.
    pub backtracks: u64,
    /// Steps served by the stack.
    pub stack_pops: u64,
    /// Steps served by the register, by where its content came from
    /// (postponed, uncle, grand uncle, grand-grand uncle).
    pub register: [u64; 4],
    /// Steps served by the hash: through the table, directly by the displacement entry.
    pub hash: [u64; 2],
    /// Steps served by iterating over links.
    pub iterative: u64,
    /// Link reads made while iterating.
    pub link_reads: u64,
    /// Restarts (kd methods).
    pub restarts: u64,
    /// Histogram of levels climbed per backtracking step (0: sibling, ..., 7: seven or more).
    pub levels: [u64; 8],
}

impl Counters {
    /// Adds another set of counters.
    pub fn add(&mut self, o: &Counters) {
        self.rays += o.rays;
        self.internal_nodes += o.internal_nodes;
        self.leaves += o.leaves;
        self.primitive_tests += o.primitive_tests;
        self.backtracks += o.backtracks;
        self.stack_pops += o.stack_pops;
        self.iterative += o.iterative;
        self.link_reads += o.link_reads;
        self.restarts += o.restarts;
        for i in 0..4 {
            self.register[i] += o.register[i];
        }
        for i in 0..2 {
            self.hash[i] += o.hash[i];
        }
        for i in 0..8 {
            self.levels[i] += o.levels[i];
        }
    }

    /// Nodes (internal and leaves) visited.
    pub fn nodes(&self) -> u64 {
        self.internal_nodes + self.leaves
    }

    /// Hash lookups (through the table or served by the displacement entry).
    pub fn hash_lookups(&self) -> u64 {
        self.hash[0] + self.hash[1]
    }
}

impl Observer for Counters {
    #[inline(always)]
    fn node(&mut self, node: NodeRef) {
        if node.is_leaf() {
            self.leaves += 1;
        } else {
            self.internal_nodes += 1;
        }
    }
    #[inline(always)]
    fn primitive(&mut self, _prim: u32) {
        self.primitive_tests += 1;
    }
    #[inline(always)]
    fn backtrack(&mut self, levels: u32, via: Backtrack) {
        self.backtracks += 1;
        self.levels[(levels as usize).min(7)] += 1;
        match via {
            Backtrack::StackPop => self.stack_pops += 1,
            Backtrack::Register(s) => self.register[s as usize] += 1,
            Backtrack::Hash { direct } => self.hash[direct as usize] += 1,
            Backtrack::Iterative => self.iterative += 1,
            Backtrack::Restart => self.restarts += 1,
        }
    }
    #[inline(always)]
    fn link_read(&mut self, _node: NodeRef) {
        self.link_reads += 1;
    }
}

/// Records the sequence of visited nodes (as layout references) and the accepted hits.
#[cfg(feature = "alloc")]
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Recorder {
    /// Visited nodes in order.
    pub nodes: alloc::vec::Vec<NodeRef>,
}

#[cfg(feature = "alloc")]
impl Observer for Recorder {
    #[inline]
    fn node(&mut self, node: NodeRef) {
        self.nodes.push(node);
    }
}

/// Feeds two observers at once.
#[derive(Debug, Default)]
pub struct Both<A, B>(pub A, pub B);

impl<A: Observer, B: Observer> Observer for Both<A, B> {
    const ENABLED: bool = A::ENABLED || B::ENABLED;
    fn node(&mut self, n: NodeRef) {
        self.0.node(n);
        self.1.node(n);
    }
    fn primitive(&mut self, p: u32) {
        self.0.primitive(p);
        self.1.primitive(p);
    }
    fn hit(&mut self, p: u32, t: f32) {
        self.0.hit(p, t);
        self.1.hit(p, t);
    }
    fn backtrack(&mut self, l: u32, v: Backtrack) {
        self.0.backtrack(l, v);
        self.1.backtrack(l, v);
    }
    fn link_read(&mut self, n: NodeRef) {
        self.0.link_read(n);
        self.1.link_read(n);
    }
}
