//! Packets of rays through a wide BVH: up to 64 rays of one direction octant share one walk of
//! the tree, one node fetch, one child order and one stack per packet. Each ray keeps its own
//! box decisions, its own answer and its own events; the packet only decides the order.
//!
//! The rule (what a reference traversal, every fast path and every backend must follow):
//! - A packet visits a child with the mask of its rays whose own box test (the single-ray test,
//!   over the ray's own interval at that moment) hits the child; every such ray records the visit.
//! - Hit children are ordered by their key, the least entry distance over the packet's rays that
//!   hit them, nearest first with ties to the smaller slot, for closest-hit queries; in slot order
//!   for any-hit queries (Guthe's unsorted occlusion). The first is visited next, the others are
//!   pushed with their masks and keys.
//! - At a leaf, every ray of the mask tests its triangles as the single-ray method does; an
//!   any-hit ray that finds one leaves the packet.
//! - A popped entry keeps the rays of its mask still in the packet, each recording a stack pop,
//!   and of those the rays whose box interval still reaches the key (a ray's own entry distance
//!   is no less than the key, so a ray dropped here would have dropped the child alone too).
//! - **Hand-over:** a child about to be visited (the root, a first child, or a popped entry) by
//!   at most [`HAND_OVER`] rays is not visited by the packet. Each of those rays, in lane order,
//!   traverses the child's subtree alone, as the single-ray method does from that child (its own
//!   order, its own stack, the step budget afresh), recording its own events; an any-hit ray
//!   answered there leaves the packet. The packet then pops its next entry.
//!
//! Closest hits are the single-ray method's bit for bit: every ray still tests every leaf whose
//! box it enters before its closest hit, and ties go to the smaller primitive id whatever the
//! order. Any-hit answers agree on occlusion (which occluder is found first may differ).
//!
//! The packet keeps its rays by lane, an array per field ([`PacketLanes`]), so that vector code
//! makes and reads eight rays per operation; a ray that goes alone gets its context made from its
//! lane. The rays' setup, the box tests of a node and the leaf tests are a [`PacketKernel`]: the
//! plain [`ReferencePacketKernel`], ray by ray, one ray and one child at a time and each ray alone
//! at a leaf, or a backend's vector code that equals it.

use super::kernel::{ChildHits, ChildKernel, ReferenceKernel};
use super::memory::WideMemory;
use super::node::{WideChild, WideNode};
use super::traverse::{leaf, visiting_order, WideRayContext, WideRoot, WideState, WIDE_STACK};
use crate::intersect::{RayContext, SlabRay, TriangleTest};
use crate::method::Query;
use crate::observe::{Backtrack, Observer};
use crate::traverse::packets::{for_each_packet, GROUPING_RAYS};
use crate::traverse::{begin_slab, QueryState};
use crate::{Hit, Ray};
use core::mem::MaybeUninit;

pub use super::WIDE_PACKET;

/// Rays at or below which a packet hands a child over to its rays (see the module docs). A box
/// test of a node for a packet costs about as much for one ray as for eight (a register of rays
/// per child), where one ray alone tests all its children at once; in the in-process A/B against
/// the packet without hand-over, 8 beat 2 and 4 on the kitchen's diffuse rays (1.27x against 1.15x
/// and 1.22x) and gained 1.1-1.5x on Sponza's and the dragon's camera, diffuse and ambient-occlusion
/// rays (`docs/notes/*-benchmarks-hand-over.md`, "The packet hands thin subtrees to its rays").
pub const HAND_OVER: u32 = 8;

/// The rays of a packet as the box tests read them: per ray (lane), the slab constants and the
/// interval a box is tested over, with bounds over the packet that a vector test may cull by.
#[derive(Clone, Copy, Debug)]
pub struct PacketRays<const N: usize> {
    /// Origins, by axis.
    pub origin: [[f32; N]; 3],
    /// Reciprocal directions, by axis.
    pub inv_dir: [[f32; N]; 3],
    /// Box interval start (`tmin - slack`; `+inf` for a lane without a ray).
    pub t_lo: [f32; N],
    /// Box interval end (`limit + slack`, following the ray's closest hit; `-inf` without a ray).
    pub t_hi: [f32; N],
    /// The slab test's slack.
    pub slack: [f32; N],
    /// Per axis, the least and greatest origin over the packet's rays.
    pub origin_range: [(f32, f32); 3],
    /// Per axis, the least and greatest reciprocal direction over the packet's rays.
    pub inv_range: [(f32, f32); 3],
    /// The least `t_lo` over the packet's rays.
    pub t_lo_min: f32,
    /// The greatest slack over the packet's rays.
    pub slack_max: f32,
    /// The greatest `t_hi` over the packet's rays still in it.
    pub t_hi_max: f32,
}

/// A packet's rays by lane, as arrays by field: the box tests' view ([`PacketRays`]), the rest of
/// each ray as given, and each ray's answer so far. A backend's vector code makes and reads eight
/// lanes per operation; a ray that must go alone (handed over, or tested by a scalar leaf) gets
/// its context and answer made from its lane ([`PacketLanes::context`], [`PacketLanes::answer`])
/// and gives the answer back ([`PacketLanes::record`]).
#[derive(Clone, Copy, Debug)]
pub struct PacketLanes<const N: usize> {
    /// The box tests' view of the lanes.
    pub rays: PacketRays<N>,
    /// Directions, by axis.
    pub dir: [[f32; N]; 3],
    /// Interval starts, as given.
    pub tmin: [f32; N],
    /// Interval ends, as given.
    pub tmax: [f32; N],
    /// Each ray's culling distance ([`QueryState::limit`]): its closest hit so far, or `tmax`.
    pub limit: [f32; N],
    /// Each ray's answer so far ([`Hit::MISS`] until one is found).
    pub hit: [Hit; N],
    /// The lanes holding a ray that [`begin_slab`] accepted (the others stay as
    /// [`PacketLanes::new`] left them and answer a miss).
    pub traced: u64,
    /// What every ray of the packet asks.
    pub query: Query,
}

/// The box tests of one node for a packet: per child slot, the rays that hit it and its key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PacketHits<const W: usize> {
    /// The least entry distance over the rays that hit each child (`+inf` where none does).
    pub key: [f32; W],
    /// The rays (bits of the packet) that hit each child.
    pub rays: [u64; W],
}

/// Tests a node's children, and a leaf, for the rays of a packet.
pub trait PacketKernel {
    /// For each child slot of `node`, the rays of `mask` whose single-ray slab test
    /// ([`SlabRay::hit_scalar`] over `[t_lo, t_hi]` with the ray's slack) hits it, and the least
    /// of their entry distances.
    fn test<const W: usize, const N: usize>(node: &WideNode<W>, rays: &PacketRays<N>, mask: u64) -> PacketHits<W>;

    /// Puts `rays` (at most `N`, at most 64; the rest is ignored) in the lanes of `lanes`, fresh
    /// from [`PacketLanes::new`]: lane `i` gets ray `i` where [`begin_slab`] accepts it, as
    /// [`PacketLanes::set_lane`] puts it, and the packet's bounds cover exactly those rays. By
    /// default ray by ray.
    #[inline(always)]
    fn begin<const N: usize>(rays: &[Ray], scene_scale: f32, lanes: &mut PacketLanes<N>) {
        for (i, ray) in rays.iter().enumerate().take(N.min(64)) {
            if let Some(slab) = begin_slab(ray, scene_scale) {
                lanes.set_lane(i, ray, &slab);
            }
        }
    }

    /// Tests leaf `(first, count)` for the rays of `mask`, each with its answer so far in
    /// `lanes`, as each ray would alone with the single-ray leaf test of `K`: the same answers,
    /// and each ray's events in the same order. By default each ray alone, in lane order.
    #[inline(always)]
    fn leaf<const W: usize, const N: usize, M, T, K, O>(
        mem: &M,
        first: u32,
        count: u32,
        mask: u64,
        lanes: &mut PacketLanes<N>,
        obs: &mut [O],
    ) where
        M: WideMemory<W> + ?Sized,
        T: TriangleTest,
        K: ChildKernel,
        O: Observer,
    {
        each_alone::<T, O, N>(mask, lanes, obs, |c, q, o| {
            leaf::<W, M, T, K, O>(mem, first, count, c, q, o);
        });
    }

    /// The rays of `mask` whose box interval still reaches `key` (`key <= t_hi`).
    #[inline(always)]
    fn reaching<const N: usize>(key: f32, rays: &PacketRays<N>, mask: u64) -> u64 {
        let mut out = 0;
        for_each_ray(mask, |i| out |= u64::from(key <= rays.t_hi[i]) << i);
        out
    }
}

/// One ray and one child at a time, through [`ReferenceKernel`]: what every fast path must equal.
#[derive(Clone, Copy, Debug, Default)]
pub struct ReferencePacketKernel;

impl PacketKernel for ReferencePacketKernel {
    fn test<const W: usize, const N: usize>(node: &WideNode<W>, rays: &PacketRays<N>, mask: u64) -> PacketHits<W> {
        let mut out = PacketHits { key: [f32::INFINITY; W], rays: [0; W] };
        let mut m = mask;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            let h = ReferenceKernel::test(node, &rays.slab(i), rays.t_lo[i], rays.t_hi[i]);
            for s in 0..W {
                if h.mask & (1 << s) != 0 {
                    out.rays[s] |= 1 << i;
                    if h.t_enter[s] < out.key[s] {
                        out.key[s] = h.t_enter[s];
                    }
                }
            }
        }
        out
    }
}

impl<const N: usize> PacketRays<N> {
    /// A packet without rays.
    pub const EMPTY: PacketRays<N> = PacketRays {
        origin: [[0.0; N]; 3],
        inv_dir: [[0.0; N]; 3],
        t_lo: [f32::INFINITY; N],
        t_hi: [f32::NEG_INFINITY; N],
        slack: [0.0; N],
        origin_range: [(f32::INFINITY, f32::NEG_INFINITY); 3],
        inv_range: [(f32::INFINITY, f32::NEG_INFINITY); 3],
        t_lo_min: f32::INFINITY,
        slack_max: 0.0,
        t_hi_max: f32::NEG_INFINITY,
    };

    /// Puts the ray of slab constants `slab`, interval start `tmin` and culling distance `limit`
    /// in lane `i` (below `N`), widening the packet's bounds to it.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, slab: &SlabRay, tmin: f32, limit: f32) {
        for a in 0..3 {
            (self.origin[a][i], self.inv_dir[a][i]) = (slab.origin[a], slab.inv_dir[a]);
            let (o, inv) = (&mut self.origin_range[a], &mut self.inv_range[a]);
            *o = (o.0.min(slab.origin[a]), o.1.max(slab.origin[a]));
            *inv = (inv.0.min(slab.inv_dir[a]), inv.1.max(slab.inv_dir[a]));
        }
        (self.t_lo[i], self.t_hi[i]) = slab.widen(tmin, limit);
        self.slack[i] = slab.slack;
        self.t_lo_min = self.t_lo_min.min(self.t_lo[i]);
        self.slack_max = self.slack_max.max(self.slack[i]);
        self.t_hi_max = self.t_hi_max.max(self.t_hi[i]);
    }

    /// Lane `i`'s slab constants (the signs of `1 / d` are `d`'s).
    pub fn slab(&self, i: usize) -> SlabRay {
        let inv = glam::Vec3A::new(self.inv_dir[0][i], self.inv_dir[1][i], self.inv_dir[2][i]);
        SlabRay {
            origin: glam::Vec3A::new(self.origin[0][i], self.origin[1][i], self.origin[2][i]),
            inv_dir: inv,
            negative: [inv.x.is_sign_negative(), inv.y.is_sign_negative(), inv.z.is_sign_negative()],
            slack: self.slack[i],
        }
    }
}

impl<const N: usize> PacketLanes<N> {
    /// A packet without rays, for `query`.
    #[inline(always)]
    pub fn new(query: Query) -> Self {
        PacketLanes {
            rays: PacketRays::EMPTY,
            dir: [[0.0; N]; 3],
            tmin: [0.0; N],
            tmax: [0.0; N],
            limit: [0.0; N],
            hit: [Hit::MISS; N],
            traced: 0,
            query,
        }
    }

    /// Puts `ray`, whose slab constants (with their slack) are `slab`, in lane `i` (below `N` and
    /// 64) with no answer yet.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, ray: &Ray, slab: &SlabRay) {
        self.rays.set_lane(i, slab, ray.tmin, ray.tmax);
        for a in 0..3 {
            self.dir[a][i] = ray.dir[a];
        }
        (self.tmin[i], self.tmax[i], self.limit[i]) = (ray.tmin, ray.tmax, ray.tmax);
        self.traced |= 1 << i;
    }

    /// Lane `i`'s ray as given.
    #[inline(always)]
    pub fn ray(&self, i: usize) -> Ray {
        let r = &self.rays;
        Ray {
            origin: [r.origin[0][i], r.origin[1][i], r.origin[2][i]],
            tmin: self.tmin[i],
            dir: [self.dir[0][i], self.dir[1][i], self.dir[2][i]],
            tmax: self.tmax[i],
        }
    }

    /// Lane `i`'s ray context, as [`begin`](crate::traverse::begin) makes it (the triangle
    /// test's constants are made on first use, afresh each time a context is made).
    #[inline(always)]
    pub fn context<T: TriangleTest>(&self, i: usize) -> WideRayContext<T> {
        RayContext::from_slab(&self.ray(i), self.rays.slab(i))
    }

    /// Lane `i`'s answer so far.
    #[inline(always)]
    pub fn answer(&self, i: usize) -> QueryState {
        QueryState::resume(self.hit[i], self.tmax[i], self.query)
    }

    /// Keeps `q` as lane `i`'s answer so far (and its culling distance).
    #[inline(always)]
    pub fn record(&mut self, i: usize, q: &QueryState) {
        (self.hit[i], self.limit[i]) = (q.hit(), q.limit());
    }

    /// Whether lane `i`'s query is answered (an any-hit ray that found a hit).
    #[inline(always)]
    pub fn is_answered(&self, i: usize) -> bool {
        self.query.is_any() && self.hit[i].is_hit()
    }
}

/// A postponed child with the rays that hit it and its key.
#[derive(Clone, Copy)]
struct Entry {
    child: WideChild,
    rays: u64,
    key: f32,
}

/// Traces one packet: `rays` (at most `N`, at most 64; the rest is ignored) over a `W`-wide tree,
/// the children tested by `P` and ordered by `K`, the leaves tested by `P` with `K`'s leaf test
/// (and the subtrees handed over walked with `K`), per the rule in the
/// module docs. Answers go to `hits`, each ray's events to its own observer in `obs`.
///
/// Inlined, so that a backend's caller compiled for a vector extension compiles all of it so.
#[inline(always)]
pub fn trace_wide_packet<
    const W: usize,
    const N: usize,
    M: WideMemory<W> + ?Sized,
    T: TriangleTest,
    K: ChildKernel,
    P: PacketKernel,
    O: Observer,
>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    query: Query,
    hits: &mut [Hit],
    obs: &mut [O],
) {
    let n = rays.len().min(N).min(64).min(hits.len()).min(obs.len());
    let mut lanes = PacketLanes::<N>::new(query);
    P::begin(&rays[..n], root.scene_scale, &mut lanes);
    let mut active = lanes.traced;
    let mut stack: [MaybeUninit<Entry>; WIDE_STACK] = [const { MaybeUninit::uninit() }; WIDE_STACK];
    let mut len = 0usize;
    let mut current = (active != 0).then_some((root.root, active));
    let mut budget = root.max_steps;
    // The single-ray state of the rays handed over (its stack storage is left uninitialized).
    let mut single = WideState::<W, K>::new(root.root);
    while let Some((child, mask)) = current {
        let hand_over = mask.count_ones() <= HAND_OVER;
        if O::ENABLED && !hand_over {
            for_each_ray(mask, |i| obs[i].node(child.node_ref()));
        }
        let next = match child {
            _ if hand_over => {
                each_alone::<T, O, N>(mask, &mut lanes, obs, |c, q, o| {
                    single.run_from(child, 0, mem, c, q, o, root.max_steps)
                });
                settle(mask, &mut lanes, &mut active);
                pop::<N, P, O>(&stack, &mut len, &lanes.rays, active, obs)
            }
            WideChild::Node(index) => {
                let node = mem.wide_node(index);
                let h = P::test::<W, N>(&node, &lanes.rays, mask);
                let hit_slots = (0..W).fold(0u32, |m, s| m | u32::from(h.rays[s] != 0) << s);
                let mut order = [0u32; W];
                let count = if hit_slots == 0 {
                    0
                } else {
                    visiting_order::<W, K>(&ChildHits { t_enter: h.key, mask: hit_slots }, query.is_any(), &mut order)
                };
                for k in (1..count).rev() {
                    let slot = order[k] as usize % W;
                    if let (Some(c), true) = (node.child_ref(slot), len < WIDE_STACK) {
                        stack[len] = MaybeUninit::new(Entry { child: c, rays: h.rays[slot], key: h.key[slot] });
                        len += 1;
                    }
                }
                let first = order[0] as usize % W;
                match node.child_ref(first).filter(|_| count > 0) {
                    Some(c) => Some((c, h.rays[first])),
                    None => pop::<N, P, O>(&stack, &mut len, &lanes.rays, active, obs),
                }
            }
            WideChild::Leaf { first, count } => {
                P::leaf::<W, N, M, T, K, O>(mem, first, count, mask, &mut lanes, obs);
                settle(mask, &mut lanes, &mut active);
                pop::<N, P, O>(&stack, &mut len, &lanes.rays, active, obs)
            }
        };
        current = match next {
            Some(c) if budget > 0 && active != 0 => {
                budget -= 1;
                Some(c)
            }
            _ => None,
        };
    }
    hits[..n].copy_from_slice(&lanes.hit[..n]);
}

/// Lets each traced ray of `mask`, in lane order, do `f` on its own (test a leaf, or walk a
/// handed-over subtree) with its context and answer so far made from its lane, and its observer;
/// keeps the answer in the lane after.
#[inline(always)]
fn each_alone<T: TriangleTest, O: Observer, const N: usize>(
    mask: u64,
    lanes: &mut PacketLanes<N>,
    obs: &mut [O],
    mut f: impl FnMut(&WideRayContext<T>, &mut QueryState, &mut O),
) {
    for_each_ray(mask & lanes.traced, |i| {
        let (c, mut q) = (lanes.context::<T>(i), lanes.answer(i));
        f(&c, &mut q, &mut obs[i]);
        lanes.record(i, &q);
    });
}

/// After the rays of `mask` tested a leaf or walked a handed-over subtree: takes an answered ray
/// out of the packet and narrows the others' box intervals to their closest hits.
#[inline(always)]
fn settle<const N: usize>(mask: u64, lanes: &mut PacketLanes<N>, active: &mut u64) {
    for_each_ray(mask & lanes.traced, |i| {
        if lanes.is_answered(i) {
            *active &= !(1 << i);
        } else {
            // The end of `SlabRay::widen`.
            lanes.rays.t_hi[i] = lanes.limit[i] + lanes.rays.slack[i];
        }
    });
    // Lanes without a ray hold `-inf`, and closest-hit rays never leave the packet; an any-hit
    // ray's interval never shrinks, so the bound stays one (if looser) as its rays leave.
    if !lanes.query.is_any() {
        lanes.rays.t_hi_max = lanes.rays.t_hi.iter().fold(f32::NEG_INFINITY, |m, &t| m.max(t));
    }
}

/// Calls `f` with each ray of `mask`, in order.
#[inline(always)]
pub fn for_each_ray(mut mask: u64, mut f: impl FnMut(usize)) {
    while mask != 0 {
        f(mask.trailing_zeros() as usize);
        mask &= mask - 1;
    }
}

/// The next postponed child with rays still looking for it (see the module docs), or `None`.
#[inline(always)]
fn pop<const N: usize, P: PacketKernel, O: Observer>(
    stack: &[MaybeUninit<Entry>; WIDE_STACK],
    len: &mut usize,
    p: &PacketRays<N>,
    active: u64,
    obs: &mut [O],
) -> Option<(WideChild, u64)> {
    while *len > 0 {
        *len -= 1;
        // SAFETY: entries below `len` were written by a push before `len` passed them.
        let e = unsafe { stack[*len].assume_init() };
        let rays = e.rays & active;
        if O::ENABLED {
            for_each_ray(rays, |i| obs[i].backtrack(0, Backtrack::StackPop));
        }
        let live = P::reaching(e.key, p, rays);
        if live != 0 {
            return Some((e.child, live));
        }
    }
    None
}

/// Traces `rays` into `hits` in the packets of the grouping ([`for_each_packet`] with
/// [`WIDE_PACKET`] rays, over chunks of [`GROUPING_RAYS`] from the start of `rays`), handing each
/// ray's index and observer to `done` once its packet is traced.
#[inline(always)]
pub fn trace_wide_packets<
    const W: usize,
    M: WideMemory<W> + ?Sized,
    T: TriangleTest,
    K: ChildKernel,
    P: PacketKernel,
    O: Observer + Default,
>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    mut done: impl FnMut(usize, O),
) {
    let n = rays.len().min(hits.len());
    for (c, chunk) in rays[..n].chunks(GROUPING_RAYS).enumerate() {
        let base = c * GROUPING_RAYS;
        // This closure holds a packet's whole traversal. The compiler inlines it into the
        // caller's AVX2 loop only while it stays small: out of line it is not compiled for AVX2,
        // and every kernel call in it stays a call (the instantiations that record enumerations
        // are out of line already). Forcing it in cost camera rays 2-3%; watch its size instead
        // (`docs/notes/*-benchmarks-leaf-blocks.md`, "A quiet morning's Embree table").
        for_each_packet(chunk, WIDE_PACKET, |idx| {
            let mut packet = [Ray { origin: [0.0; 3], tmin: 0.0, dir: [0.0; 3], tmax: 0.0 }; WIDE_PACKET];
            for (k, &i) in idx.iter().enumerate() {
                packet[k] = chunk[i as usize];
            }
            let mut out = [Hit::MISS; WIDE_PACKET];
            let mut obs: [O; WIDE_PACKET] = core::array::from_fn(|_| O::default());
            trace_wide_packet::<W, WIDE_PACKET, M, T, K, P, O>(
                mem,
                root,
                &packet[..idx.len()],
                query,
                &mut out,
                &mut obs,
            );
            for ((k, &i), o) in idx.iter().enumerate().zip(obs) {
                hits[base + i as usize] = out[k];
                done(base + i as usize, o);
            }
        });
    }
}
