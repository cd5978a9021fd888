use super::{intersect_leaf, order_children, Descent};
use crate::bvh2::{BvhMemory, NodeRef};
use crate::intersect::{RayContext, TriangleTest};
use crate::observe::{Backtrack, Observer};
use crate::traverse::{Machine, QueryState, Step};

/// Deepest stack needed: one entry per level of a tree of depth 63.
const CAPACITY: usize = 64;

/// Method (a): stack-based traversal in the "while-while" order of Aila & Laine (2009) without
/// speculative traversal: descend to the closer child, push the other, pop at a leaf or a dead
/// end. With `DISJOINT`, each entry remembers whether its t-interval was disjoint from its
/// sibling's, and a hit in a leaf drops those entries: the same pruning rule as the mask of
/// method (e), for comparing enumerations.
#[derive(Clone, Copy, Debug)]
pub struct StackState<const DISJOINT: bool> {
    addr: NodeRef,
    len: usize,
    stack: [NodeRef; CAPACITY],
    /// Bit `i`: entry `i` is behind a disjoint interval (used only with `DISJOINT`).
    disjoint: u64,
}

impl<const DISJOINT: bool> StackState<DISJOINT> {
    /// Starts at `root`.
    #[inline(always)]
    pub fn new(root: NodeRef) -> Self {
        Self { addr: root, len: 0, stack: [NodeRef::NONE; CAPACITY], disjoint: 0 }
    }

    /// Starts over at `root` for another ray. The stack's storage is kept as it is: entries above
    /// its top are never read, so a batch sets the stack up once rather than once per ray.
    #[inline(always)]
    pub fn restart(&mut self, root: NodeRef) {
        self.addr = root;
        self.len = 0;
        self.disjoint = 0;
    }
}

impl<M: BvhMemory + ?Sized, T: TriangleTest, const DISJOINT: bool> Machine<M, RayContext<T>> for StackState<DISJOINT> {
    /// Processes one node; see [`Step`].
    #[inline(always)]
    fn step<O: Observer>(&mut self, mem: &M, ctx: &RayContext<T>, q: &mut QueryState, obs: &mut O) -> Step {
        // Only damaged tables lead to an absent node; end rather than read out of bounds.
        if self.addr.is_none() {
            return Step::Done;
        }
        obs.node(self.addr);
        if !self.addr.is_leaf() {
            let node = mem.read_node(self.addr.index());
            match order_children(&node, ctx, q.limit()) {
                Descent::One(i) => {
                    self.addr = node.children[i];
                    return Step::Continue;
                }
                Descent::Both { first, disjoint } => {
                    // A tree of depth <= 63 never has more than 63 postponed nodes.
                    if self.len < CAPACITY {
                        self.stack[self.len] = node.children[1 - first];
                        if DISJOINT {
                            self.disjoint = (self.disjoint & !(1 << self.len)) | ((disjoint as u64) << self.len);
                        }
                        self.len += 1;
                    }
                    self.addr = node.children[first];
                    return Step::Continue;
                }
                Descent::Neither => return self.pop(obs, false),
            }
        }
        let (_, hit) = intersect_leaf(mem, self.addr.offset(), ctx, q, obs);
        if q.is_answered() {
            return Step::Done;
        }
        if DISJOINT && hit {
            self.drop_disjoint();
        }
        self.pop(obs, hit)
    }
}

impl<const DISJOINT: bool> StackState<DISJOINT> {
    #[inline(always)]
    fn pop<O: Observer>(&mut self, obs: &mut O, after_hit: bool) -> Step {
        if self.len == 0 {
            return Step::Done;
        }
        self.len -= 1;
        self.addr = self.stack[self.len];
        obs.backtrack(0, Backtrack::StackPop);
        if after_hit {
            Step::AfterHit
        } else {
            Step::Continue
        }
    }

    /// Removes the entries whose interval was disjoint, keeping the others in order.
    fn drop_disjoint(&mut self) {
        let mut kept = 0;
        for i in 0..self.len {
            if self.disjoint & (1 << i) == 0 {
                self.stack[kept] = self.stack[i];
                kept += 1;
            }
        }
        self.len = kept;
        self.disjoint = 0;
    }
}
