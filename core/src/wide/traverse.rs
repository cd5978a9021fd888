//! The wide-BVH traversal (Guthe 2014): a stack of (child, entry distance), all children of a node
//! tested at once, hit children nearest first for closest-hit queries and unsorted for any-hit
//! queries (Sec. 4.2: all hit children but one are pushed, none sorted).

use super::kernel::{ChildHits, ChildKernel};
use super::memory::WideMemory;
use super::node::{WideChild, WideNode, EMPTY_CHILD};
use crate::bvh2::NodeRef;
use crate::intersect::{BlockHits, NoPair, RayContext, TriangleHit, TriangleTest, BLOCK};
use crate::method::Query;
use crate::observe::{Backtrack, Observer};
use crate::traverse::{for_each_ray, Machine, QueryState, Step};
use crate::{Hit, Ray};
use core::marker::PhantomData;
use core::mem::MaybeUninit;

/// Stack entries: enough for `W - 1` postponed children on each of 63 levels, `W` up to 8.
pub const WIDE_STACK: usize = 448;

/// The context of a wide traversal: the slab constants alone are its box constants.
pub type WideRayContext<T> = RayContext<T, NoPair>;

/// Where a wide traversal starts, with the scene constants every ray needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WideRoot {
    /// The root: node 0, or a leaf for a one-leaf tree.
    pub root: WideChild,
    /// The largest coordinate magnitude in the scene (as for the BVH2 methods, so the slack is
    /// theirs).
    pub scene_scale: f32,
    /// Steps after which traversal stops (never binds on an intact tree).
    pub max_steps: u32,
}

/// One ray's traversal state: the child being visited, and the postponed children with the entry
/// distances they were found at. `K` tests and orders each node's children.
///
/// The stack's storage is left uninitialized: only the entries below `len` are ever read, and each
/// was written by a push first, so a ray traced on its own does not pay for writing all
/// [`WIDE_STACK`] entries (5 KiB) up front.
#[derive(Clone, Debug)]
pub struct WideState<const W: usize, K: ChildKernel> {
    current: Option<WideChild>,
    len: usize,
    stack: [MaybeUninit<Postponed>; WIDE_STACK],
    kernel: PhantomData<K>,
}

impl<const W: usize, K: ChildKernel> WideState<W, K> {
    /// Starts at `root`.
    pub fn new(root: WideChild) -> Self {
        Self { current: Some(root), len: 0, stack: [const { MaybeUninit::uninit() }; WIDE_STACK], kernel: PhantomData }
    }
}

impl<const W: usize, M: WideMemory<W> + ?Sized, T: TriangleTest, K: ChildKernel> Machine<M, WideRayContext<T>>
    for WideState<W, K>
{
    /// Processes one node or leaf; see [`Step`].
    #[inline(always)]
    fn step<O: Observer>(&mut self, mem: &M, ctx: &WideRayContext<T>, q: &mut QueryState, obs: &mut O) -> Step {
        let Some(current) = self.current else { return Step::Done };
        obs.node(current.node_ref());
        let after_hit = match current {
            WideChild::Node(index) => match expand::<W, M, T, K>(&mut self.stack, &mut self.len, mem, index, ctx, q) {
                Expanded::Next(c) => {
                    self.current = c.decode();
                    return Step::Continue;
                }
                Expanded::EmptyFirst => {
                    self.current = None;
                    return Step::Continue;
                }
                Expanded::NoneHit => false,
            },
            WideChild::Leaf { first, count } => {
                let hit = leaf::<W, M, T, K, O>(mem, first, count, ctx, q, obs);
                if q.is_answered() {
                    return Step::Done;
                }
                hit
            }
        };
        self.current = pop(&self.stack, &mut self.len, ctx, q, obs).and_then(SlotWords::decode);
        match self.current {
            None => Step::Done,
            Some(_) if after_hit => Step::AfterHit,
            Some(_) => Step::Continue,
        }
    }

    /// [`Machine::run`] as one loop, with the node being visited and the stack height in locals
    /// rather than in `self` between steps, so that they stay in registers: 5-15% faster than
    /// stepping (`docs/notes/*-benchmarks-one-loop.md`, "One loop per ray"). The transitions are
    /// `step`'s, in its order, so the answer and the events are the same.
    #[inline(always)]
    fn run<O: Observer>(&mut self, mem: &M, ctx: &WideRayContext<T>, q: &mut QueryState, obs: &mut O, max_steps: u32) {
        if let Some(current) = self.current {
            self.run_from(current, self.len, mem, ctx, q, obs, max_steps);
        }
    }
}

impl<const W: usize, K: ChildKernel> WideState<W, K> {
    /// [`Machine::run`] from `current` with `len` entries on the stack, the stack's storage
    /// reused: the batch loop and a packet's hand-over start each ray here, its start in
    /// registers. (Written into the state by a restart and read back by `run`, it cost 7% of a
    /// single ray's time: `docs/notes/*-one-driver-one-dispatch.md`, "Checks".)
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn run_from<M: WideMemory<W> + ?Sized, T: TriangleTest, O: Observer>(
        &mut self,
        current: WideChild,
        mut len: usize,
        mem: &M,
        ctx: &WideRayContext<T>,
        q: &mut QueryState,
        obs: &mut O,
        max_steps: u32,
    ) {
        let mut budget = max_steps;
        let mut at = SlotWords::of(current);
        loop {
            obs.node(at.node_ref());
            let next = if at.count == 0 {
                match expand::<W, M, T, K>(&mut self.stack, &mut len, mem, at.child, ctx, q) {
                    Expanded::Next(c) => Some(c),
                    // `step` leaves no node to visit: its next call ends the ray.
                    Expanded::EmptyFirst => {
                        self.current = None;
                        return;
                    }
                    Expanded::NoneHit => pop(&self.stack, &mut len, ctx, q, obs),
                }
            } else {
                leaf::<W, M, T, K, O>(mem, at.child, at.count, ctx, q, obs);
                if q.is_answered() {
                    self.current = None;
                    return;
                }
                pop(&self.stack, &mut len, ctx, q, obs)
            };
            match next {
                Some(c) if budget > 0 => {
                    budget -= 1;
                    at = c;
                }
                _ => {
                    (self.current, self.len) = (next.and_then(SlotWords::decode), len);
                    return;
                }
            }
        }
    }
}

/// A postponed child as its slot holds it (the node's words, copied without a branch), decoded
/// when popped. Decoding it at the push took a branch per pushed child on whether it is an empty
/// slot, a node or a leaf; pushing the words instead gained 1.5-3% on the interiors
/// (`docs/notes/*-benchmarks-packet-leaves.md`, "The wide stack pushes a child's slot words"),
/// likely mispredictions saved on scattered rays (there were no counters to tell). An empty slot,
/// which no box test hits on an intact tree, is dropped at the pop before any event, so the events
/// are those of never pushing it.
#[derive(Clone, Copy, Debug)]
struct Postponed {
    slot: SlotWords,
    t_enter: f32,
}

/// A child slot's two words (see [`WideNode`]'s layout): an internal node where `count` is 0, a
/// leaf otherwise, an empty slot where `child` is [`EMPTY_CHILD`] (stacked, never visited: the
/// pop drops it). The single-ray loop carries this form and tells node from leaf by `count`
/// alone; building a [`WideChild`] at every visit and matching it again took a select, a spill and
/// a second test per visit (`docs/notes/*-single-ray-selects.md`).
#[derive(Clone, Copy, Debug)]
struct SlotWords {
    child: u32,
    count: u32,
}

impl SlotWords {
    /// The words of `c`.
    #[inline(always)]
    fn of(c: WideChild) -> Self {
        let (child, count) = c.words();
        Self { child, count }
    }

    /// The words of `node`'s child slot `slot` (an empty slot's too).
    #[inline(always)]
    fn at<const W: usize>(node: &WideNode<W>, slot: usize) -> Self {
        Self { child: node.child[slot], count: node.count[slot] }
    }

    /// The child these words refer to (`None` only for an empty slot's words, which the walk
    /// never carries).
    #[inline(always)]
    fn decode(self) -> Option<WideChild> {
        WideChild::from_words(self.child, self.count)
    }

    /// [`WideChild::node_ref`] of the child.
    #[inline(always)]
    fn node_ref(self) -> NodeRef {
        if self.count == 0 {
            NodeRef::internal(self.child)
        } else {
            NodeRef::leaf(self.child)
        }
    }
}

/// What testing an internal node's children left to do.
enum Expanded {
    /// Visit this child next (the others hit are on the stack).
    Next(SlotWords),
    /// The first child in order is an empty slot (never, on an intact tree): nothing to visit.
    EmptyFirst,
    /// No child is hit: go back to the stack.
    NoneHit,
}

/// Tests node `index`'s children and pushes all hit ones but the first onto `stack` (of height
/// `len`), farthest first so that the next nearest is popped next: nearest first for closest-hit
/// queries, slot order for any-hit queries (Guthe's unsorted occlusion).
#[inline(always)]
fn expand<const W: usize, M: WideMemory<W> + ?Sized, T: TriangleTest, K: ChildKernel>(
    stack: &mut [MaybeUninit<Postponed>; WIDE_STACK],
    len: &mut usize,
    mem: &M,
    index: u32,
    ctx: &WideRayContext<T>,
    q: &QueryState,
) -> Expanded {
    let node = mem.wide_node(index);
    let (lo, hi) = ctx.box_interval(q.limit());
    let hits = K::test::<W>(&node, &ctx.slab, lo, hi);
    if hits.mask == 0 {
        return Expanded::NoneHit;
    }
    // As early as the hit children are known, so that their loads overlap the ordering below.
    mem.prefetch_hit_children(&node, hits.mask);
    let rest = hits.mask & (hits.mask - 1);
    let nearest = if rest & rest.wrapping_sub(1) == 0 {
        // One or two children hit, most nodes on scattered rays: the pair ordered without the
        // order array or a branch on which of the two counts it is (that branch missed 2.4 times
        // a ray on Sponza's shuffled diffuse rays, whose rays visit about 8 internal nodes). The
        // order is `visiting_order`'s: the nearer first, a tie (or an unsorted any-hit query) in
        // slot order.
        let first = hits.mask.trailing_zeros() as usize % W;
        let second = if rest != 0 { rest.trailing_zeros() as usize % W } else { first };
        let (near, far) = if !q.any || K::SORTED_ANY {
            // The swap as arithmetic on the slots: written as an `if`, it compiled to a branch
            // that missed 1.1 times a ray.
            let swap = usize::from(hits.t_enter[second] < hits.t_enter[first]);
            let near = first ^ ((first ^ second) & swap.wrapping_neg());
            (near, near ^ first ^ second)
        } else {
            // Slot order: the next child follows from the hit mask alone, not from the entry
            // distances (a longer chain of dependent operations before the next node's loads).
            (first, second)
        };
        // The farther one is written either way and counted only where there are two: an entry
        // past `len` is never read, and the count needs no branch.
        if *len < WIDE_STACK {
            stack[*len] = MaybeUninit::new(Postponed { slot: SlotWords::at(&node, far), t_enter: hits.t_enter[far] });
            *len += usize::from(rest != 0);
        }
        near
    } else {
        let mut order = [0u32; W];
        let n = visiting_order::<W, K>(&hits, q.any, &mut order);
        for k in (1..n).rev() {
            let slot = order[k] as usize % W;
            if *len < WIDE_STACK {
                stack[*len] =
                    MaybeUninit::new(Postponed { slot: SlotWords::at(&node, slot), t_enter: hits.t_enter[slot] });
                *len += 1;
            }
        }
        order[0] as usize % W
    };
    match node.child[nearest] {
        EMPTY_CHILD => Expanded::EmptyFirst,
        _ => Expanded::Next(SlotWords::at(&node, nearest)),
    }
}

/// Writes the hit slots of `hits` to `order` in the order they are visited and returns how many
/// there are: nearest first (`K::order`) for closest-hit queries, slot order for any-hit ones
/// (Guthe's unsorted occlusion) unless `K` sorts those too.
#[inline(always)]
pub(crate) fn visiting_order<const W: usize, K: ChildKernel>(
    hits: &ChildHits<W>,
    any: bool,
    order: &mut [u32; W],
) -> usize {
    if any && !K::SORTED_ANY {
        let (mut m, mut n) = (hits.mask, 0);
        while m != 0 {
            order[n] = m.trailing_zeros();
            m &= m - 1;
            n += 1;
        }
        n
    } else {
        K::order::<W>(hits, order)
    }
}

/// The nearest postponed child that may still hold a closer hit, popped from `stack` (of height
/// `len`): one entered beyond the closest hit by more than the ray's slack cannot (a triangle's
/// computed `t` strays from its box's interval by less), so it is dropped unvisited. `None` when
/// the stack runs out.
#[inline(always)]
fn pop<O: Observer>(
    stack: &[MaybeUninit<Postponed>; WIDE_STACK],
    len: &mut usize,
    ctx: &WideRayContext<impl TriangleTest>,
    q: &QueryState,
    obs: &mut O,
) -> Option<SlotWords> {
    while *len > 0 {
        *len -= 1;
        // SAFETY: entries below `len` were written by a push before `len` passed them (`len`
        // only grows by a push that writes the entry it passes), and `len` was above this one.
        let e = unsafe { stack[*len].assume_init() };
        if e.slot.child == EMPTY_CHILD {
            continue;
        }
        obs.backtrack(0, Backtrack::StackPop);
        if e.t_enter <= q.limit() + ctx.t_slack {
            return Some(e.slot);
        }
    }
    None
}

/// Tests the ray against the `count` triangles from position `first`; returns whether a hit was
/// taken. An any-hit query stops at its first hit.
///
/// With [`ChildKernel::BLOCKS`], four triangles at a time, all four against the limit the block
/// starts with, then offered in order: a triangle that a hit earlier in the block would have
/// culled is refused by the offer instead (it is farther, or tied with a larger id), so the answer
/// and the events are those of one triangle at a time.
#[inline(always)]
pub(crate) fn leaf<const W: usize, M: WideMemory<W> + ?Sized, T: TriangleTest, K: ChildKernel, O: Observer>(
    mem: &M,
    first: u32,
    count: u32,
    ctx: &WideRayContext<T>,
    q: &mut QueryState,
    obs: &mut O,
) -> bool {
    leaf_with::<W, M, T, K, O>(mem, first, count, &ctx.tri(), ctx.ray.tmin, q, obs)
}

/// [`leaf`] with the ray's triangle constants and interval start given (a stream keeps them
/// apart from the rest of a ray's context).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn leaf_with<const W: usize, M: WideMemory<W> + ?Sized, T: TriangleTest, K: ChildKernel, O: Observer>(
    mem: &M,
    first: u32,
    count: u32,
    per_ray: &T::PerRay,
    tmin: f32,
    q: &mut QueryState,
    obs: &mut O,
) -> bool {
    let mut taken = false;
    let end = first + count;
    let mut pos = first;
    while pos < end {
        let (hits, n) = if K::BLOCKS {
            let block = mem.wide_block(pos / BLOCK as u32);
            (T::intersect_block(per_ray, &block, tmin, q.limit()), (end - pos).min(BLOCK as u32))
        } else {
            let tri = mem.wide_triangle(pos);
            let [a, b, c] = &*tri;
            let mut hits = BlockHits::NONE;
            hits.set(0, T::intersect_in_place(per_ray, [a.as_ref(), b.as_ref(), c.as_ref()], tmin, q.limit()));
            (hits, 1)
        };
        let live = hits.mask & ((1 << n) - 1);
        if O::ENABLED {
            // Every triangle tested is an event, up to an any-hit query's answer.
            for lane in 0..n as usize {
                let prim = mem.prim(pos + lane as u32);
                obs.primitive(prim);
                if let Some(h) = hits.get(lane).filter(|_| live & (1 << lane) != 0) {
                    if q.offer(h, prim) {
                        obs.hit(prim, h.t);
                        taken = true;
                        if q.any {
                            return true;
                        }
                    }
                }
            }
        } else {
            // The same offers, visiting only the lanes hit: a branch per hit, not per lane.
            let mut m = live;
            while m != 0 {
                let lane = m.trailing_zeros() as usize;
                let prim = mem.prim(pos + lane as u32);
                let h = TriangleHit { t: hits.t[lane], u: hits.u[lane], v: hits.v[lane] };
                if q.offer(h, prim) {
                    taken = true;
                    if q.any {
                        return true;
                    }
                }
                m &= m - 1;
            }
        }
        pos += n;
    }
    taken
}

/// Traces `rays` into `hits` (pairs up to the shorter of the two) over a `W`-wide tree, the
/// children tested and ordered by `K`, with the stack set up once per batch.
#[inline]
pub fn trace_wide_batch<const W: usize, M: WideMemory<W> + ?Sized, T: TriangleTest, K: ChildKernel, O: Observer>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    obs: &mut O,
) {
    let mut state = WideState::<W, K>::new(root.root);
    for_each_ray::<T, NoPair>(rays, hits, root.scene_scale, query, |ctx, q| {
        // The triangle test's constants made here rather than at the first leaf: nearly every
        // ray reaches a leaf, and the check at each leaf whether they were made yet missed 0.6
        // times a ray on shuffled diffuse rays (LLVM had hoisted most of the work here anyway).
        ctx.tri();
        state.run_from(root.root, 0, mem, ctx, q, obs, root.max_steps);
    });
}

/// Traces one ray over a `W`-wide tree; see [`trace_wide_batch`].
#[inline]
pub fn trace_wide_ray<const W: usize, M: WideMemory<W> + ?Sized, T: TriangleTest, K: ChildKernel, O: Observer>(
    mem: &M,
    root: WideRoot,
    ray: &Ray,
    query: Query,
    obs: &mut O,
) -> Hit {
    let mut hit = Hit::MISS;
    trace_wide_batch::<W, M, T, K, O>(
        mem,
        root,
        core::slice::from_ref(ray),
        core::slice::from_mut(&mut hit),
        query,
        obs,
    );
    hit
}
