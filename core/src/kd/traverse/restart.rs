use super::{cross, kd_leaf, Crossing};
use crate::bvh2::NodeRef;
use crate::intersect::{KdRayContext, TriangleTest};
use crate::kd::KdMemory;
use crate::observe::{Backtrack, Observer};
use crate::traverse::{Machine, QueryState, Step};

/// Most entries a short stack may keep.
pub const SHORT_STACK_MAX: usize = 16;

/// How a restarting kd traversal backtracks: whether the restart point moves down (A.3) and how
/// many entries its short stack keeps (A.4; 0: none).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RestartPolicy {
    /// The restart point follows descents that entered a single child.
    pub push_down: bool,
    /// Entries of the short stack, at most [`SHORT_STACK_MAX`].
    pub short_stack: usize,
}

impl RestartPolicy {
    /// kd-restart (A.2): back to the root after every leaf.
    pub const RESTART: RestartPolicy = RestartPolicy { push_down: false, short_stack: 0 };
    /// Push-down (A.3).
    pub const PUSH_DOWN: RestartPolicy = RestartPolicy { push_down: true, short_stack: 0 };

    /// Short-stack (A.4): push-down and a stack of `entries`.
    pub const fn short_stack(entries: usize) -> RestartPolicy {
        RestartPolicy { push_down: true, short_stack: entries }
    }
}

/// kd-restart and its refinements (Horn et al. 2007, A.2-A.4), one state for the three:
/// - restart (A.2): no stack, no push-down: after a leaf, step the segment's start to the leaf's
///   exit and descend again from the root;
/// - push-down (A.3): while a descent has entered only one child at every node, the restart point
///   moves down with it, so later restarts begin at the lowest node enclosing the rest of the ray;
/// - short-stack (A.4): push-down plus a stack of at most `capacity` entries; a push onto a full
///   stack drops the bottom entry, and popping an empty one restarts.
#[derive(Clone, Copy, Debug)]
pub struct KdRestartState {
    node: u32,
    t_min: f32,
    t_max: f32,
    scene_max: f32,
    /// Where a restart begins (the root, or lower with push-down).
    restart_at: u32,
    push_down: bool,
    /// Whether the current descent has met only single-child nodes since it began.
    pushing: bool,
    capacity: usize,
    len: usize,
    stack: [(u32, f32, f32); SHORT_STACK_MAX],
}

impl KdRestartState {
    /// Starts at the root over `[t_min, scene_max]`, backtracking as `policy` says.
    #[inline(always)]
    pub fn new(t_min: f32, scene_max: f32, policy: RestartPolicy) -> Self {
        let RestartPolicy { push_down, short_stack: capacity } = policy;
        Self {
            node: 0,
            t_min,
            t_max: scene_max,
            scene_max,
            restart_at: 0,
            push_down,
            pushing: push_down,
            capacity: capacity.min(SHORT_STACK_MAX),
            len: 0,
            stack: [(0, 0.0, 0.0); SHORT_STACK_MAX],
        }
    }
}

impl<M: KdMemory + ?Sized, T: TriangleTest> Machine<M, KdRayContext<T>> for KdRestartState {
    /// Processes one node; see [`Step`].
    #[inline(always)]
    fn step<O: Observer>(&mut self, mem: &M, ctx: &KdRayContext<T>, q: &mut QueryState, obs: &mut O) -> Step {
        let n = mem.kd_node(self.node);
        if !n.is_leaf() {
            obs.node(NodeRef::internal(self.node));
            match cross(&n, &ctx.slab, self.t_min, self.t_max) {
                Crossing::First(c) | Crossing::Second(c) => {
                    self.node = c;
                    if self.pushing {
                        self.restart_at = c;
                    }
                }
                Crossing::Both { first, second, t_split } => {
                    self.push(second, t_split, self.t_max);
                    self.node = first;
                    self.t_max = t_split;
                    self.pushing = false;
                }
            }
            return Step::Continue;
        }
        if kd_leaf(mem, self.node, &n, self.t_max, ctx, q, obs) {
            return Step::Done;
        }
        if self.len > 0 {
            self.len -= 1;
            (self.node, self.t_min, self.t_max) = self.stack[self.len];
            self.pushing = false;
            obs.backtrack(0, Backtrack::StackPop);
            return Step::Continue;
        }
        if self.t_max >= self.scene_max {
            return Step::Done;
        }
        self.node = self.restart_at;
        self.t_min = self.t_max;
        self.t_max = self.scene_max;
        self.pushing = self.push_down;
        obs.backtrack(0, Backtrack::Restart);
        Step::Continue
    }
}

impl KdRestartState {
    #[inline(always)]
    fn push(&mut self, node: u32, t_min: f32, t_max: f32) {
        if self.capacity == 0 {
            return;
        }
        if self.len == self.capacity {
            // Full: the bottom entry (farthest along the ray) is dropped; a restart will find it.
            self.stack.copy_within(1..self.len, 0);
            self.len -= 1;
        }
        self.stack[self.len] = (node, t_min, t_max);
        self.len += 1;
    }
}
