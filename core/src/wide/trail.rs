//! Stackless traversal of a wide BVH: Binder & Keller's (2016) node keys, bit trail and perfect
//! hash carried from two children per node to `W` (keys of [`super::keyed`]). Beyond both papers:
//! a ray's whole state is its current child, its key, its trail and one register (16 bytes with
//! 32-bit keys), where the stack traversal ([`super::traverse`]) keeps up to `W - 1` entries per
//! level.
//!
//! **The trail** has one bit per level, relative to the current node as in the binary method: bit
//! `i` is set where the ancestor `i` levels up (bit 0: the node itself) may still have siblings to
//! visit after it. A binary node's trail bit names its one sibling; a wide node may have up to
//! `W - 1` siblings left, in an order given by entry distances that one bit cannot hold. So
//! **backtracking** takes `n`, the trail's trailing zeros, finds the parent of the ancestor `n`
//! levels up through the perfect hash in constant time (its key shifted right by `b (n + 1)`
//! bits), tests that parent's child boxes again, and goes on to the next child after the
//! ancestor's slot in the visiting order among those still worth visiting. That is one hash
//! lookup and one node's box tests per backtrack, whatever the depth, instead of a stack pop.
//!
//! **A register** spares most lookups, as Binder & Keller's most-recently-postponed-node register
//! does for the binary tree: it holds the parent of the level of the trail's lowest set bit, when
//! known. A node whose expansion leaves siblings to visit writes itself there; a backtrack that
//! finds more siblings after the one it takes keeps it; one that exhausts its level empties it
//! (the parent of the next level up is not known, so the hash finds it).
//!
//! **The same nodes as the stack traversal, in the same order.** The stack pushes a node's hit
//! children after the first in the visiting order, and pops each when its entry distance is within
//! the slack of the closest hit (`t_enter <= limit + slack`). The re-test here runs over
//! `[tmin - slack, +inf]`: the same entry distances as at the expansion (they do not depend on the
//! far end), and a box hit over the expansion's interval is hit over this one. Conversely a box hit
//! over this one with `t_enter <= limit + slack` was hit at the expansion too: its exit distance
//! was either the same, or cut by the expansion's far end `limit' + slack >= limit + slack`, which
//! the test's own slack then covers (rounding is monotonic). So the children taken here are the
//! stack's entries that its pops keep, in the same order, and the enumeration is the stack
//! traversal's node for node; the trail only changes how the next one is found.

use super::kernel::{ChildHits, ChildKernel};
use super::keyed::{child_key, slot_bits, WideKeyedMemory};
use super::node::WideChild;
use super::traverse::{leaf, visiting_order, WideRayContext, WideRoot};
use crate::intersect::TriangleTest;
use crate::key::Key;
use crate::method::Query;
use crate::observe::{Backtrack, Observer, RegisterSource};
use crate::traverse::{for_each_ray, Machine, QueryState, Step};
use crate::{Hit, Ray};
use core::marker::PhantomData;

/// One ray's stackless state: the child being visited, its key and trail, and the register (the
/// parent of the level of the trail's lowest set bit, where known). `K` is wide enough for the
/// tree's depth ([`super::keyed::wide_key_width`]); `C` tests and orders each node's children.
#[derive(Clone, Copy, Debug)]
pub struct WideTrailState<const W: usize, K: Key, C: ChildKernel> {
    current: Option<WideChild>,
    key: K,
    trail: K,
    register: Option<u32>,
    kernel: PhantomData<C>,
}

impl<const W: usize, K: Key, C: ChildKernel> WideTrailState<W, K, C> {
    /// Starts at `root` (key 1, empty trail, empty register).
    #[inline(always)]
    pub fn new(root: WideChild) -> Self {
        Self { current: Some(root), key: K::ONE, trail: K::ZERO, register: None, kernel: PhantomData }
    }
}

impl<const W: usize, K: Key, C: ChildKernel> WideTrailState<W, K, C> {
    /// Visits `current` and moves `current`, `key` and `trail` to the child after it: descends
    /// to the first child in the visiting order, or backtracks through the register or the hash.
    /// Returns `false` when the ray is done (they are then left as they were). The one transition
    /// of both [`Machine::step`] and [`Machine::run`], in place so that `run` keeps them in
    /// registers.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn visit<M: WideKeyedMemory<W> + ?Sized, T: TriangleTest, O: Observer>(
        current: &mut WideChild,
        key: &mut K,
        trail: &mut K,
        register: &mut Option<u32>,
        mem: &M,
        ctx: &WideRayContext<T>,
        q: &mut QueryState,
        obs: &mut O,
    ) -> bool {
        obs.node(current.node_ref());
        match *current {
            WideChild::Node(index) => {
                let node = mem.wide_node(index);
                let (lo, hi) = ctx.box_interval(q.limit());
                let hits = C::test::<W>(&node, &ctx.slab, lo, hi);
                if hits.mask != 0 {
                    let mut order = [0u32; W];
                    let n = visiting_order::<W, C>(&hits, q.any, &mut order);
                    let Some(first) = node.child_ref(order[0] as usize) else { return false };
                    *current = first;
                    *key = child_key::<W, K>(*key, order[0]);
                    *trail = trail.shl(1) | if n > 1 { K::ONE } else { K::ZERO };
                    if n > 1 {
                        *register = Some(index);
                    }
                    return true;
                }
            }
            WideChild::Leaf { first, count } => {
                leaf::<W, M, T, C, O>(mem, first, count, ctx, q, obs);
                if q.is_answered() {
                    return false;
                }
            }
        }
        match backtrack::<W, K, M, T, C, O>(mem, *key, *trail, register, ctx, q, obs) {
            Some((next, k, t)) => {
                (*current, *key, *trail) = (next, k, t);
                true
            }
            None => false,
        }
    }
}

impl<const W: usize, K: Key, M: WideKeyedMemory<W> + ?Sized, T: TriangleTest, C: ChildKernel>
    Machine<M, WideRayContext<T>> for WideTrailState<W, K, C>
{
    /// Visits one node or leaf; see [`Step`]. (The walk does not pause, so it reports no
    /// [`Step::AfterHit`].)
    #[inline(always)]
    fn step<O: Observer>(&mut self, mem: &M, ctx: &WideRayContext<T>, q: &mut QueryState, obs: &mut O) -> Step {
        let Some(mut current) = self.current else { return Step::Done };
        if Self::visit(&mut current, &mut self.key, &mut self.trail, &mut self.register, mem, ctx, q, obs) {
            self.current = Some(current);
            Step::Continue
        } else {
            self.current = None;
            Step::Done
        }
    }

    /// [`Machine::run`] as one loop with the walk's registers in locals, as the stack walk's
    /// ([`WideState`](super::traverse::WideState)): `step`'s transitions in its order.
    #[inline(always)]
    fn run<O: Observer>(&mut self, mem: &M, ctx: &WideRayContext<T>, q: &mut QueryState, obs: &mut O, max_steps: u32) {
        if let Some(current) = self.current {
            let (key, trail, register) = (self.key, self.trail, self.register);
            self.run_from(current, key, trail, register, mem, ctx, q, obs, max_steps);
        }
    }
}

impl<const W: usize, K: Key, C: ChildKernel> WideTrailState<W, K, C> {
    /// [`Machine::run`] from `current` with its key, trail and register: the batch loop starts
    /// each ray here, its start in registers rather than written into a state and read back (as
    /// for the stack walk: `docs/notes/*-one-driver-one-dispatch.md`, "Checks").
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn run_from<M: WideKeyedMemory<W> + ?Sized, T: TriangleTest, O: Observer>(
        &mut self,
        mut current: WideChild,
        mut key: K,
        mut trail: K,
        mut register: Option<u32>,
        mem: &M,
        ctx: &WideRayContext<T>,
        q: &mut QueryState,
        obs: &mut O,
        max_steps: u32,
    ) {
        let mut budget = max_steps;
        while Self::visit(&mut current, &mut key, &mut trail, &mut register, mem, ctx, q, obs) {
            if budget == 0 {
                *self = Self { current: Some(current), key, trail, register, kernel: PhantomData };
                return;
            }
            budget -= 1;
        }
        self.current = None;
    }
}

/// The next child to visit after the subtree of the node keyed `key` is done, with its key and
/// trail, or `None` when the trail runs out (the ray is done). `register` is the parent of the
/// first level tried, where known, and is left holding the parent of the returned child's level
/// when more of its siblings remain.
#[inline(always)]
fn backtrack<const W: usize, K: Key, M: WideKeyedMemory<W> + ?Sized, T: TriangleTest, C: ChildKernel, O: Observer>(
    mem: &M,
    mut key: K,
    mut trail: K,
    register: &mut Option<u32>,
    ctx: &WideRayContext<T>,
    q: &QueryState,
    obs: &mut O,
) -> Option<(WideChild, K, K)> {
    let b = slot_bits::<W>();
    while !trail.is_zero() {
        let n = trail.trailing_zeros();
        // The ancestor whose later siblings may be due, its slot and its parent.
        let ancestor = key.shr(b * n);
        let slot = ancestor.low_u32() & (W as u32 - 1);
        let parent_key = ancestor.shr(b);
        let parent = match register.take() {
            Some(p) => {
                obs.backtrack(n, Backtrack::Register(RegisterSource::Postponed));
                p
            }
            None => {
                let (p, direct) = mem.keyed_node(parent_key);
                obs.backtrack(n, Backtrack::Hash { direct });
                p
            }
        };
        let node = mem.wide_node(parent);
        let (lo, _) = ctx.box_interval(q.limit());
        let hits = C::test::<W>(&node, &ctx.slab, lo, f32::INFINITY);
        // The trail is now relative to the ancestor, its bit consumed.
        (key, trail) = (ancestor, trail.shr(n) ^ K::ONE);
        let (next, more) = successor(&hits, slot, q.limit() + ctx.t_slack, q.any && !C::SORTED_ANY);
        if let Some(s) = next {
            let child = node.child_ref(s as usize)?;
            if more {
                *register = Some(parent);
                trail = trail | K::ONE;
            }
            return Some((child, child_key::<W, K>(parent_key, s), trail));
        }
    }
    None
}

/// The child visited after slot `current` among `hits` (tested over `[tmin - slack, +inf]`), and
/// whether more remain after it: of the hit children entered within `reach`, the least after
/// `current` by (entry distance, slot), or by slot alone for unsorted any-hit queries.
#[inline(always)]
pub fn successor<const W: usize>(hits: &ChildHits<W>, current: u32, reach: f32, by_slot: bool) -> (Option<u32>, bool) {
    let cur = hits.t_enter[current as usize % W];
    let after = |s: u32, t: f32| if by_slot { s > current } else { t > cur || (t == cur && s > current) };
    let (mut best, mut count) = (None::<(f32, u32)>, 0);
    let mut m = hits.mask;
    while m != 0 {
        let s = m.trailing_zeros();
        m &= m - 1;
        let t = hits.t_enter[s as usize % W];
        if t <= reach && after(s, t) {
            count += 1;
            // Slots come in increasing order, so a tie keeps the smaller one.
            if best.is_none_or(|(bt, _)| !by_slot && t < bt) {
                best = Some((t, s));
            }
        }
    }
    (best.map(|(_, s)| s), count > 1)
}

/// Traces `rays` into `hits` (pairs up to the shorter of the two) over a `W`-wide tree without a
/// stack, the children tested and ordered by `C`.
#[inline]
pub fn trace_wide_trail_batch<
    const W: usize,
    K: Key,
    M: WideKeyedMemory<W> + ?Sized,
    T: TriangleTest,
    C: ChildKernel,
    O: Observer,
>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    obs: &mut O,
) {
    for_each_ray::<T, crate::intersect::NoPair>(rays, hits, root.scene_scale, query, |ctx, q| {
        let mut state = WideTrailState::<W, K, C>::new(root.root);
        state.run_from(root.root, K::ONE, K::ZERO, None, mem, ctx, q, obs, root.max_steps);
    });
}

/// Traces one ray over a `W`-wide tree without a stack; see [`trace_wide_trail_batch`].
#[inline]
pub fn trace_wide_trail_ray<
    const W: usize,
    K: Key,
    M: WideKeyedMemory<W> + ?Sized,
    T: TriangleTest,
    C: ChildKernel,
    O: Observer,
>(
    mem: &M,
    root: WideRoot,
    ray: &Ray,
    query: Query,
    obs: &mut O,
) -> Hit {
    let mut hit = Hit::MISS;
    let (rays, hits) = (core::slice::from_ref(ray), core::slice::from_mut(&mut hit));
    trace_wide_trail_batch::<W, K, M, T, C, O>(mem, root, rays, hits, query, obs);
    hit
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hits(t: [f32; 4], mask: u32) -> ChildHits<4> {
        ChildHits { t_enter: t, mask }
    }

    #[test]
    fn successor_follows_the_visiting_order() {
        // Slots 0..4 entered at 3, 1, 2, 1: the order is 1, 3, 2, 0.
        let h = hits([3.0, 1.0, 2.0, 1.0], 0b1111);
        assert_eq!(successor(&h, 1, f32::INFINITY, false), (Some(3), true));
        assert_eq!(successor(&h, 3, f32::INFINITY, false), (Some(2), true));
        assert_eq!(successor(&h, 2, f32::INFINITY, false), (Some(0), false));
        assert_eq!(successor(&h, 0, f32::INFINITY, false), (None, false));
        // Beyond reach: slot 0 (entered at 3) is dropped.
        assert_eq!(successor(&h, 3, 2.5, false), (Some(2), false));
        // By slot for unsorted any-hit queries.
        assert_eq!(successor(&h, 1, f32::INFINITY, true), (Some(2), true));
        assert_eq!(successor(&h, 2, f32::INFINITY, true), (Some(3), false));
        // Missed children never follow.
        assert_eq!(successor(&hits([3.0, 1.0, 2.0, 1.0], 0b0011), 1, f32::INFINITY, false), (Some(0), false));
        // Zeros of both signs tie and keep slot order.
        assert_eq!(successor(&hits([0.0, -0.0, 0.0, 1.0], 0b1111), 0, f32::INFINITY, false), (Some(1), true));
    }
}
