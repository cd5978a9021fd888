use super::{cross, kd_leaf, Crossing};
use crate::bvh2::NodeRef;
use crate::intersect::{KdRayContext, TriangleTest};
use crate::kd::KdMemory;
use crate::observe::{Backtrack, Observer};
use crate::traverse::{Machine, QueryState, Step};
use core::mem::MaybeUninit;

/// Deepest stack a kd-tree of depth 64 can need.
const CAPACITY: usize = 64;

/// The standard stack traversal (Horn et al. 2007, A.1; Wald 2004): descend to the child met
/// first, push the other with its part of the segment, pop at a leaf.
///
/// The stack's storage is left uninitialized, as the wide traversal's is: only entries below
/// `len` are read, each written by a push first. Zeroing its 768 bytes was a store per ray the
/// rest of the ray then waited behind.
#[derive(Clone, Copy, Debug)]
pub struct KdStackState {
    node: u32,
    t_min: f32,
    t_max: f32,
    len: usize,
    stack: [MaybeUninit<Entry>; CAPACITY],
}

/// A postponed far child with its part of the segment.
type Entry = (u32, f32, f32);

/// Where a traversal stands between transitions: the node and the segment of the ray inside it,
/// and the stack height. [`KdStackState::step`] keeps it in the state; [`KdStackState::run`] in
/// locals, so that it stays in registers.
struct Cursor {
    node: u32,
    t_min: f32,
    t_max: f32,
    len: usize,
}

impl KdStackState {
    /// Starts at the root over the ray's segment inside the scene, `[t_min, t_max]`.
    #[inline(always)]
    pub fn new(t_min: f32, t_max: f32) -> Self {
        Self { node: 0, t_min, t_max, len: 0, stack: [MaybeUninit::uninit(); CAPACITY] }
    }
}

impl<M: KdMemory + ?Sized, T: TriangleTest> Machine<M, KdRayContext<T>> for KdStackState {
    /// Processes one node; see [`Step`].
    #[inline(always)]
    fn step<O: Observer>(&mut self, mem: &M, ctx: &KdRayContext<T>, q: &mut QueryState, obs: &mut O) -> Step {
        let mut c = Cursor { node: self.node, t_min: self.t_min, t_max: self.t_max, len: self.len };
        let step = advance(&mut c, &mut self.stack, mem, ctx, q, obs);
        (self.node, self.t_min, self.t_max, self.len) = (c.node, c.t_min, c.t_max, c.len);
        step
    }

    /// [`Machine::run`] as one loop with the cursor in locals
    /// (`docs/notes/*-benchmarks-one-loop.md`, "One loop per ray"): the same transitions in the
    /// same order, so the same answer and events.
    #[inline(always)]
    fn run<O: Observer>(&mut self, mem: &M, ctx: &KdRayContext<T>, q: &mut QueryState, obs: &mut O, max_steps: u32) {
        let mut c = Cursor { node: self.node, t_min: self.t_min, t_max: self.t_max, len: self.len };
        let mut budget = max_steps;
        while advance(&mut c, &mut self.stack, mem, ctx, q, obs) != Step::Done && budget > 0 {
            budget -= 1;
        }
        (self.node, self.t_min, self.t_max, self.len) = (c.node, c.t_min, c.t_max, c.len);
    }
}

/// One transition from `c`.
#[inline(always)]
fn advance<M: KdMemory + ?Sized, T: TriangleTest, O: Observer>(
    c: &mut Cursor,
    stack: &mut [MaybeUninit<Entry>; CAPACITY],
    mem: &M,
    ctx: &KdRayContext<T>,
    q: &mut QueryState,
    obs: &mut O,
) -> Step {
    let n = mem.kd_node(c.node);
    if !n.is_leaf() {
        obs.node(NodeRef::internal(c.node));
        match cross(&n, &ctx.slab, c.t_min, c.t_max) {
            Crossing::First(child) | Crossing::Second(child) => c.node = child,
            Crossing::Both { first, second, t_split } => {
                // Depth is capped at 64, so the stack never holds more than 64 entries.
                if c.len < CAPACITY {
                    stack[c.len] = MaybeUninit::new((second, t_split, c.t_max));
                    c.len += 1;
                }
                c.node = first;
                c.t_max = t_split;
            }
        }
        return Step::Continue;
    }
    if kd_leaf(mem, c.node, &n, c.t_max, ctx, q, obs) || c.len == 0 {
        return Step::Done;
    }
    c.len -= 1;
    // SAFETY: entries below `len` were written by a push before `len` passed them (`len` only
    // grows by a push that writes the entry it passes), and `len` was above this one.
    (c.node, c.t_min, c.t_max) = unsafe { stack[c.len].assume_init() };
    obs.backtrack(0, Backtrack::StackPop);
    Step::Continue
}
