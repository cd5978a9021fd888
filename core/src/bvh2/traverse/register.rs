use super::{intersect_leaf, order_children, Descent};
use crate::bvh2::{BvhMemory, NodeRef};
use crate::hash::lookup;
use crate::intersect::{RayContext, TriangleTest};
use crate::key::{self, Key};
use crate::observe::{Backtrack, Observer, RegisterSource};
use crate::traverse::{Machine, QueryState, Step};

/// How a [`RegisterState`] finds the next node when the register is empty.
pub trait Fallback {
    /// Finds the sibling of the ancestor `levels` levels above the current node, whose key is
    /// `key` (already the target's key) and whose first links are `links` (`depth_known` of them:
    /// 2 for an internal node, 3 for a leaf).
    fn find<K: Key, M: BvhMemory + ?Sized, O: Observer>(
        mem: &M,
        key: K,
        levels: u32,
        links: &[NodeRef; 3],
        obs: &mut O,
    ) -> NodeRef;
}

/// Method (d): the perfect hash maps the target's key to its address in constant time
/// (Algorithm 1, the `else` branch of backtracking).
#[derive(Clone, Copy, Debug, Default)]
pub struct PerfectHashLookup;

impl Fallback for PerfectHashLookup {
    #[inline(always)]
    fn find<K: Key, M: BvhMemory + ?Sized, O: Observer>(
        mem: &M,
        key: K,
        levels: u32,
        _links: &[NodeRef; 3],
        obs: &mut O,
    ) -> NodeRef {
        let (r, direct) = lookup(mem, mem.hash_shape(), key);
        obs.backtrack(levels, Backtrack::Hash { direct });
        r
    }
}

/// Method (c): iterative backtracking over uncle links (Sec. 2.2, side note). The current node
/// knows the siblings of its ancestors one and two levels up (a leaf also three); beyond them,
/// each hop reads the farthest known one's own uncle and grand uncle, climbing two levels per
/// read instead of the one per read of parent links.
#[derive(Clone, Copy, Debug, Default)]
pub struct UncleHops;

impl Fallback for UncleHops {
    #[inline(always)]
    fn find<K: Key, M: BvhMemory + ?Sized, O: Observer>(
        mem: &M,
        _key: K,
        levels: u32,
        links: &[NodeRef; 3],
        obs: &mut O,
    ) -> NodeRef {
        // `links[j - 1]` is the sibling of the ancestor `j` levels up; a leaf's third link is
        // only in its terminator, so hops use the first two, which every node has at a fixed place.
        let mut known = if links[2].is_none() { 2 } else { 3 };
        let (mut have, mut rest) = (*links, levels);
        while rest > known {
            let via = have[known as usize - 1];
            if via.is_none() {
                return NodeRef::NONE;
            }
            rest -= known;
            obs.link_read(via);
            let [a, b] = mem.hop_links(via);
            have = [a, b, NodeRef::NONE];
            known = 2;
        }
        obs.backtrack(levels, Backtrack::Iterative);
        // `rest` is at least 1: a target one level up or less is always in the register.
        have[rest.max(1) as usize - 1]
    }
}

/// Methods (c), (d) and (e): stackless traversal with a node key, a bit trail and the
/// most-recently-postponed-node register (Binder & Keller 2016, Algorithm 1).
///
/// When both children are hit, the farther one goes into the register. When the register is
/// empty, every node loaded refills it from its links if the trail says its uncle or grand uncle
/// (a leaf: also grand-grand uncle) is the next target. Backtracking shifts key and trail by the
/// trail's trailing zeros and flips their lowest bit; the register serves the step if set, else
/// the [`Fallback`]. With `DISJOINT` (method e), a second trail marks levels whose child
/// t-intervals overlap; a hit in a leaf masks the bit trail with it (Sec. 2.3), and empties the
/// register if its level was masked out.
#[derive(Clone, Copy, Debug)]
pub struct RegisterState<K: Key, F: Fallback, const DISJOINT: bool> {
    addr: NodeRef,
    key: K,
    trail: K,
    /// The most recently postponed node, or [`NodeRef::NONE`].
    mrpn: NodeRef,
    /// Bit per level: the child intervals there overlap (kept by the mask). Only with `DISJOINT`.
    overlap: K,
    /// Where the register's content came from; written only for an enabled observer.
    source: RegisterSource,
    fallback: core::marker::PhantomData<F>,
}

impl<K: Key, F: Fallback, const DISJOINT: bool> RegisterState<K, F, DISJOINT> {
    /// Starts at `root` (key 1, empty trail, empty register).
    #[inline(always)]
    pub fn new(root: NodeRef) -> Self {
        Self::resume_at(root, key::root(), K::ZERO)
    }

    /// Starts at node `addr` with the given key and trail, register empty (Sec. 2.4).
    #[inline(always)]
    pub fn resume_at(addr: NodeRef, key: K, trail: K) -> Self {
        Self {
            addr,
            key,
            trail,
            mrpn: NodeRef::NONE,
            overlap: K::ZERO,
            source: RegisterSource::Postponed,
            fallback: core::marker::PhantomData,
        }
    }

    /// The node key and bit trail of the next node to process.
    #[inline(always)]
    pub fn key_and_trail(&self) -> (K, K) {
        (self.key, self.trail)
    }
}

impl<M: BvhMemory + ?Sized, T: TriangleTest, K: Key, F: Fallback, const DISJOINT: bool> Machine<M, RayContext<T>>
    for RegisterState<K, F, DISJOINT>
{
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
            if self.mrpn.is_none() {
                self.refill::<O>([node.links[0], node.links[1], NodeRef::NONE]);
            }
            let (right, postpone, disjoint) = match order_children(&node, ctx, q.limit()) {
                Descent::One(i) => (i == 1, false, false),
                Descent::Both { first, disjoint } => {
                    self.mrpn = node.children[1 - first];
                    if O::ENABLED {
                        self.source = RegisterSource::Postponed;
                    }
                    (first == 1, true, disjoint)
                }
                Descent::Neither => {
                    let links = [node.links[0], node.links[1], NodeRef::NONE];
                    return self.backtrack::<M, O>(mem, &links, obs, Step::Continue);
                }
            };
            self.addr = node.children[right as usize];
            (self.key, self.trail) = key::descend(self.key, self.trail, right, postpone);
            if DISJOINT {
                self.overlap = self.overlap.shl(1) | if postpone && !disjoint { K::ONE } else { K::ZERO };
            }
            return Step::Continue;
        }
        let (links, hit) = intersect_leaf(mem, self.addr.offset(), ctx, q, obs);
        if q.is_answered() {
            return Step::Done;
        }
        if DISJOINT && hit {
            if (self.trail.lowest_bit() & self.overlap).is_zero() {
                self.mrpn = NodeRef::NONE;
            }
            self.trail = self.trail & self.overlap;
        }
        if self.mrpn.is_none() {
            self.refill::<O>(links);
        }
        self.backtrack::<M, O>(mem, &links, obs, if hit { Step::AfterHit } else { Step::Continue })
    }
}

impl<K: Key, F: Fallback, const DISJOINT: bool> RegisterState<K, F, DISJOINT> {
    /// Loads the register from the current node's links when the trail names one of them as the
    /// next target: the lowest set trail bit among 1..=3 (bit 0 is never set with an empty
    /// register, since postponing a sibling fills it).
    #[inline(always)]
    fn refill<O: Observer>(&mut self, links: [NodeRef; 3]) {
        const SOURCES: [RegisterSource; 3] =
            [RegisterSource::Uncle, RegisterSource::GrandUncle, RegisterSource::GrandGrandUncle];
        let bits = self.trail.shr(1).low_u32() & 0b111;
        if bits != 0 {
            let j = bits.trailing_zeros() as usize;
            // Absent links (NONE) leave the register empty: their level is above the root.
            self.mrpn = links[j];
            if O::ENABLED {
                self.source = SOURCES[j];
            }
        }
    }

    #[inline(always)]
    fn backtrack<M: BvhMemory + ?Sized, O: Observer>(
        &mut self,
        mem: &M,
        links: &[NodeRef; 3],
        obs: &mut O,
        more: Step,
    ) -> Step {
        let Some((k, t, levels)) = key::backtrack(self.key, self.trail) else {
            return Step::Done;
        };
        (self.key, self.trail) = (k, t);
        if DISJOINT {
            self.overlap = self.overlap.shr(levels);
        }
        if !self.mrpn.is_none() {
            self.addr = self.mrpn;
            self.mrpn = NodeRef::NONE;
            obs.backtrack(levels, Backtrack::Register(self.source));
        } else {
            self.addr = F::find(mem, k, levels, links, obs);
        }
        more
    }
}
