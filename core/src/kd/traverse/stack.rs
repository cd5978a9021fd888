use super::{cross, kd_leaf, Crossing};
use crate::bvh2::NodeRef;
use crate::intersect::{KdRayContext, TriangleTest};
use crate::kd::KdMemory;
use crate::observe::{Backtrack, Observer};
use crate::traverse::{QueryState, Step};

/// Deepest stack a kd-tree of depth 64 can need.
const CAPACITY: usize = 64;

/// The standard stack traversal (Horn et al. 2007, A.1; Wald 2004): descend to the child met
/// first, push the other with its part of the segment, pop at a leaf.
#[derive(Clone, Copy, Debug)]
pub struct KdStackState {
    node: u32,
    t_min: f32,
    t_max: f32,
    len: usize,
    stack: [(u32, f32, f32); CAPACITY],
}

impl KdStackState {
    /// Starts at the root over the ray's segment inside the scene, `[t_min, t_max]`.
    #[inline(always)]
    pub fn new(t_min: f32, t_max: f32) -> Self {
        Self { node: 0, t_min, t_max, len: 0, stack: [(0, 0.0, 0.0); CAPACITY] }
    }

    /// Processes one node; see [`Step`].
    #[inline(always)]
    pub fn step<M: KdMemory + ?Sized, T: TriangleTest, O: Observer>(
        &mut self,
        mem: &M,
        ctx: &KdRayContext<T>,
        q: &mut QueryState,
        obs: &mut O,
    ) -> Step {
        let n = mem.kd_node(self.node);
        if !n.is_leaf() {
            obs.node(NodeRef::internal(self.node));
            match cross(&n, &ctx.slab, self.t_min, self.t_max) {
                Crossing::First(c) | Crossing::Second(c) => self.node = c,
                Crossing::Both { first, second, t_split } => {
                    // Depth is capped at 64, so the stack never holds more than 64 entries.
                    if self.len < CAPACITY {
                        self.stack[self.len] = (second, t_split, self.t_max);
                        self.len += 1;
                    }
                    self.node = first;
                    self.t_max = t_split;
                }
            }
            return Step::Continue;
        }
        if kd_leaf(mem, self.node, &n, self.t_max, ctx, q, obs) || self.len == 0 {
            return Step::Done;
        }
        self.len -= 1;
        (self.node, self.t_min, self.t_max) = self.stack[self.len];
        obs.backtrack(0, Backtrack::StackPop);
        Step::Continue
    }
}
