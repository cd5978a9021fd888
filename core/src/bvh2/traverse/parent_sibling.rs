use super::{intersect_leaf, order_children, Descent};
use crate::bvh2::{BvhMemory, NodeRef};
use crate::intersect::{RayContext, TriangleTest};
use crate::key::Key;
use crate::observe::{Backtrack, Observer};
use crate::traverse::{Machine, QueryState, Step};

/// Method (b): stackless traversal with parent and sibling links and a bit trail (Áfra, Szirmay-
/// Kalos and Keller 2014). Backtracking climbs parent links until the trail shows a postponed
/// sibling, then follows that sibling link; an empty trail ends traversal without returning to
/// the root. Needs the [`LinkKind::ParentSibling`](crate::bvh2::LinkKind) layout.
#[derive(Clone, Copy, Debug)]
pub struct ParentSiblingState<K: Key> {
    addr: NodeRef,
    trail: K,
}

impl<K: Key> ParentSiblingState<K> {
    /// Starts at `root`.
    #[inline(always)]
    pub fn new(root: NodeRef) -> Self {
        Self { addr: root, trail: K::ZERO }
    }
}

impl<M: BvhMemory + ?Sized, T: TriangleTest, K: Key> Machine<M, RayContext<T>> for ParentSiblingState<K> {
    /// Processes one node; see [`Step`].
    #[inline(always)]
    fn step<O: Observer>(&mut self, mem: &M, ctx: &RayContext<T>, q: &mut QueryState, obs: &mut O) -> Step {
        // Only damaged tables lead to an absent node; end rather than read out of bounds.
        if self.addr.is_none() {
            return Step::Done;
        }
        obs.node(self.addr);
        let links = if !self.addr.is_leaf() {
            let node = mem.read_node(self.addr.index());
            match order_children(&node, ctx, q.limit()) {
                Descent::One(i) => {
                    self.trail = self.trail.shl(1);
                    self.addr = node.children[i];
                    return Step::Continue;
                }
                Descent::Both { first, .. } => {
                    self.trail = self.trail.shl(1) ^ K::ONE;
                    self.addr = node.children[first];
                    return Step::Continue;
                }
                Descent::Neither => node.links,
            }
        } else {
            let (l, _) = intersect_leaf(mem, self.addr.offset(), ctx, q, obs);
            if q.is_answered() {
                return Step::Done;
            }
            [l[0], l[1]]
        };
        self.backtrack(mem, links, obs)
    }
}

impl<K: Key> ParentSiblingState<K> {
    /// Climbs from the current node, whose `[parent, sibling]` links are given.
    #[inline(always)]
    fn backtrack<M: BvhMemory + ?Sized, O: Observer>(&mut self, mem: &M, mut links: [NodeRef; 2], obs: &mut O) -> Step {
        if self.trail.is_zero() {
            return Step::Done;
        }
        let mut levels = 0;
        while (self.trail & K::ONE).is_zero() {
            let parent = links[0];
            if parent.is_none() || parent.is_leaf() {
                return Step::Done;
            }
            obs.link_read(parent);
            links = mem.read_node(parent.index()).links;
            self.trail = self.trail.shr(1);
            levels += 1;
        }
        self.trail = self.trail ^ K::ONE;
        self.addr = links[1];
        obs.backtrack(levels, Backtrack::Iterative);
        Step::Continue
    }
}
