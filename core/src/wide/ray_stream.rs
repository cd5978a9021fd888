//! Rays through a wide BVH as one stream per chunk (dynamic ray-stream traversal, Barringer and
//! Akenine-Möller 2014): a node is fetched once for all the rays of the stream that reach it, each
//! of them tests its children with its own single-ray box test, and the rays that hit a child go
//! on in that child's list. On interiors a node near the root is reached by thousands of a
//! chunk's rays, so the load a single diffuse ray waits for at each visit is paid once, and the
//! rays' box tests are independent work rather than one chain of latencies.
//!
//! The rule (what the reference, every fast path and every backend must follow):
//! - Rays are traced in streams of [`STREAM_RAYS`] consecutive rays of the batch, from its start.
//! - A stream visits a child with the list of its rays whose own box test (the single-ray test,
//!   over the ray's own interval at that moment) hits the child; every ray of the list records
//!   the visit. Lists are in the order of the rays in the batch.
//! - A node's hit children are ordered by their key, the least entry distance over the rays that
//!   hit them, nearest first with ties to the smaller slot, for closest-hit queries; in slot order
//!   for any-hit ones (Guthe's unsorted occlusion). The first is visited next with all its rays;
//!   the others are pushed with their lists, each ray with its own entry distance (onto a full
//!   stack of [`WIDE_STACK`] entries, none is: the single-ray traversal's bound).
//! - At a leaf, every ray of the list, in list order, tests its triangles as the single-ray method
//!   does; an any-hit ray that finds one leaves the stream.
//! - A popped entry: every ray of its list still in the stream records a stack pop, and those
//!   whose own entry distance is still within their interval (the single-ray pop's test) visit
//!   the child. An entry that no ray reaches is dropped.
//! - Unlike a packet, a stream hands no subtree to single rays: thin lists stay in the stream
//!   (handing them over reloaded what the stream had in cache:
//!   `docs/notes/*-benchmarks-bvh8-stream.md`, "A ray-stream prototype").
//!
//! Where the memory prefetches ([`WideMemory::PREFETCHES`]: a tree larger than the caches), a
//! node's hit children are asked for as soon as its box tests have named them, so that their
//! loads overlap the ordering and the lists: on the 871k-triangle dragon's diffuse rays 1.13-1.21x
//! (`docs/notes/*-benchmarks-stream-prefetch.md`, "Streams that prefetch").
//!
//! Closest hits are the single-ray method's bit for bit (every ray still tests every leaf whose
//! box it enters before its closest hit, and ties go to the smaller primitive id whatever the
//! order); any-hit answers agree on occlusion. A ray's events depend on the other rays of its
//! stream only through the order of the visits, never through the order within a list.

use super::kernel::{ChildHits, ChildKernel, StreamRay};
use super::memory::WideMemory;
use super::node::WideChild;
use super::traverse::{leaf_with, visiting_order, WideRoot, WIDE_STACK};
use crate::intersect::{NoPair, TriangleTest};
use crate::method::Query;
use crate::observe::{Backtrack, Observer};
use crate::traverse::{begin, QueryState};
use crate::{Hit, Ray};
use alloc::vec::Vec;

pub use super::STREAM_RAYS;

/// A postponed child and where its list lies in the buffer of lists.
#[derive(Clone, Copy)]
struct Entry {
    child: WideChild,
    start: usize,
    len: usize,
}

/// A list entry: a ray (by its place in the stream) and its entry distance, as one word so the
/// lists are written with one store per entry.
#[inline(always)]
fn item(ray: u32, t: f32) -> u64 {
    u64::from(ray) | (u64::from(t.to_bits()) << 32)
}

/// The ray and the entry distance of a list entry.
#[inline(always)]
fn unpack(item: u64) -> (usize, f32) {
    ((item as u32) as usize, f32::from_bits((item >> 32) as u32))
}

/// The working memory of a stream, kept from one stream to the next.
struct StreamScratch<const W: usize, T: TriangleTest, O> {
    /// Each traced ray's box constants and interval (what a node's box tests read), triangle
    /// constants, answer and observer, and its place in the chunk. Kept apart rather than as whole
    /// contexts: a ray's leaves read its triangle constants, made once, rather than the lazily
    /// made copy inside a context that also holds the ray and its slab constants (1.08-1.10x on
    /// the interiors' diffuse rays:
    /// `docs/notes/*-benchmarks-bvh8-stream.md`, "`bvh8-stream` on every backend").
    rays: Vec<StreamRay>,
    tri: Vec<T::PerRay>,
    q: Vec<QueryState>,
    obs: Vec<O>,
    place: Vec<u32>,
    /// Whether each ray is still in the stream (an answered any-hit ray is not).
    active: Vec<bool>,
    /// The lists of the postponed children, the nearest on top.
    items: Vec<u64>,
    stack: Vec<Entry>,
    /// The rays visiting the current child.
    live: Vec<u32>,
    /// Per ray of `live`: its hit mask and entry distances at the current node.
    masks: Vec<u32>,
    t_enter: Vec<[f32; W]>,
}

/// List entries reserved per ray of a stream, up front: the lists of the postponed children grow
/// past it where they must.
const ITEMS_PER_RAY: usize = 8;

impl<const W: usize, T: TriangleTest, O> StreamScratch<W, T, O> {
    /// Buffers with room for streams of `rays` rays, each allocated once. Grown from empty, they
    /// were reallocated and copied a dozen times in every stream, and each parallel task (one
    /// stream) makes its own scratch.
    fn with_capacity(rays: usize) -> Self {
        Self {
            rays: Vec::with_capacity(rays),
            tri: Vec::with_capacity(rays),
            q: Vec::with_capacity(rays),
            obs: Vec::with_capacity(rays),
            place: Vec::with_capacity(rays),
            active: Vec::with_capacity(rays),
            items: Vec::with_capacity(rays * ITEMS_PER_RAY),
            stack: Vec::with_capacity(WIDE_STACK),
            live: Vec::with_capacity(rays + 1),
            masks: Vec::with_capacity(rays),
            t_enter: Vec::with_capacity(rays),
        }
    }
}

/// Traces `rays` into `hits` (pairs up to the shorter of the two) in streams of [`STREAM_RAYS`],
/// the children tested and ordered by `K`, the leaves tested with `K`'s leaf test, per the rule in
/// the module docs; hands each ray's index and observer to `done` once its stream is traced.
/// Inlined, so that a backend's caller compiled for a vector extension compiles all of it so.
#[inline(always)]
pub fn trace_wide_streams<
    const W: usize,
    M: WideMemory<W> + ?Sized,
    T: TriangleTest,
    K: ChildKernel,
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
    let mut s = StreamScratch::<W, T, O>::with_capacity(n.min(STREAM_RAYS));
    for (c, chunk) in rays[..n].chunks(STREAM_RAYS).enumerate() {
        let base = c * STREAM_RAYS;
        trace_wide_stream::<W, M, T, K, O>(mem, root, chunk, query, &mut s);
        // A ray that `begin` turned away is a miss with no events.
        hits[base..base + chunk.len()].fill(Hit::MISS);
        let mut traced = 0;
        for i in 0..chunk.len() {
            if s.place.get(traced).is_some_and(|&p| p as usize == i) {
                hits[base + i] = s.q[traced].hit();
                done(base + i, core::mem::take(&mut s.obs[traced]));
                traced += 1;
            } else {
                done(base + i, O::default());
            }
        }
    }
}

/// Traces one stream of `rays` per the module docs; each traced ray's place in `rays` (in
/// increasing order), answer and observer are left in `s`.
#[inline(always)]
fn trace_wide_stream<
    const W: usize,
    M: WideMemory<W> + ?Sized,
    T: TriangleTest,
    K: ChildKernel,
    O: Observer + Default,
>(
    mem: &M,
    root: WideRoot,
    rays: &[Ray],
    query: Query,
    s: &mut StreamScratch<W, T, O>,
) {
    s.rays.clear();
    s.tri.clear();
    s.q.clear();
    s.obs.clear();
    s.place.clear();
    s.active.clear();
    s.items.clear();
    s.stack.clear();
    s.live.clear();
    for (i, ray) in rays.iter().enumerate() {
        let Some((c, q)) = begin::<T, NoPair>(ray, root.scene_scale, query) else { continue };
        s.live.push(s.rays.len() as u32);
        s.rays.push(StreamRay { slab: c.slab, interval: c.box_interval(q.limit()), tmin: c.ray.tmin });
        s.tri.push(c.tri());
        s.q.push(q);
        s.obs.push(O::default());
        s.place.push(i as u32);
        s.active.push(true);
    }
    let mut current = (!s.live.is_empty()).then_some(root.root);
    let mut budget = root.max_steps;
    while let Some(child) = current {
        if O::ENABLED {
            for &r in &s.live {
                s.obs[r as usize].node(child.node_ref());
            }
        }
        let next = match child {
            WideChild::Node(index) => expand::<W, M, T, K, O>(mem, index, query, s),
            WideChild::Leaf { first, count } => {
                for &r in &s.live {
                    let r = r as usize;
                    let (ray, q) = (&mut s.rays[r], &mut s.q[r]);
                    leaf_with::<W, M, T, K, O>(mem, first, count, &s.tri[r], ray.tmin, q, &mut s.obs[r]);
                    if q.is_answered() {
                        s.active[r] = false;
                        ray.interval.1 = f32::NEG_INFINITY;
                    } else {
                        ray.interval.1 = ray.slab.widen(ray.tmin, q.limit()).1;
                    }
                }
                None
            }
        };
        current = match next.or_else(|| pop(s)) {
            Some(c) if budget > 0 => {
                budget -= 1;
                Some(c)
            }
            _ => None,
        };
    }
}

/// Tests node `index`'s children for the rays of `s.live`, pushes the hit children but the first
/// with their lists, and leaves the first child's rays in `s.live`; `None` when no child is hit.
#[inline(always)]
fn expand<const W: usize, M: WideMemory<W> + ?Sized, T: TriangleTest, K: ChildKernel, O: Observer>(
    mem: &M,
    index: u32,
    query: Query,
    s: &mut StreamScratch<W, T, O>,
) -> Option<WideChild> {
    let node = mem.wide_node(index);
    let n = s.live.len();
    // Grown only, never refilled: the box tests write every entry they read back.
    if s.masks.len() < n {
        s.masks.resize(n, 0);
        s.t_enter.resize(n, [f32::INFINITY; W]);
    }
    let (masks, t_enter) = (&mut s.masks[..n], &mut s.t_enter[..n]);
    let (mut counts, mut keys) = ([0u32; W], [f32::INFINITY; W]);
    K::stream_node::<W>(&node, &s.live, &s.rays, masks, t_enter, &mut keys, &mut counts);
    let hit_slots = (0..W).fold(0u32, |m, c| m | u32::from(counts[c] > 0) << c);
    if hit_slots == 0 {
        return None;
    }
    // As early as the hit children are known, so that their loads overlap the ordering and the
    // lists below (the single-ray walk's prefetch; the memory decides whether it does anything).
    mem.prefetch_hit_children(&node, hit_slots);
    let mut order = [0u32; W];
    let count = visiting_order::<W, K>(&ChildHits { t_enter: keys, mask: hit_slots }, query.is_any(), &mut order);
    // A list per pushed child, in visiting order from the farthest, so that the nearest pushed
    // one's lies on top; each padded by one entry, so that every ray writes to the list and moves
    // on only where it hit (a write without a branch).
    let spare = s.items.len();
    let mut at = [spare; W];
    let mut end = spare + 1;
    for k in (1..count).rev() {
        let slot = order[k] as usize % W;
        at[slot] = end;
        end += counts[slot] as usize + 1;
        if s.stack.len() < WIDE_STACK {
            if let Some(c) = node.child_ref(slot) {
                s.stack.push(Entry { child: c, start: end - counts[slot] as usize - 1, len: counts[slot] as usize });
            }
        }
    }
    s.items.resize(end, 0);
    // One pass over the rays per pushed child: the write position stays in a register.
    for &slot in &order[1..count] {
        let c = slot as usize % W;
        let mut to = at[c];
        for ((&r, &m), t_enter) in s.live.iter().zip(&*masks).zip(&*t_enter) {
            // SAFETY: `to` stays within `items`: the child's list has one entry to spare beyond
            // its count of rays, and only a ray that hit it moves `to` on.
            unsafe { *s.items.get_unchecked_mut(to) = item(r, t_enter[c]) };
            to += ((m >> c) & 1) as usize;
        }
    }
    // The last list's pad (or the spare entry) leaves the buffer.
    s.items.truncate(end - 1);
    // The first child's rays visit it with no test of their entry distance (a ray goes straight
    // on to its nearest child, as it would alone): they stay in `live`, in order, compacted in
    // place (a ray is never written past where it is read) without a branch.
    let first = order[0] as usize % W;
    let mut to = 0;
    for (k, &m) in masks.iter().enumerate() {
        s.live[to] = s.live[k];
        to += ((m >> first) & 1) as usize;
    }
    s.live.truncate(to);
    node.child_ref(first)
}

/// The next postponed child that some ray still reaches, with those rays in `s.live` (see the
/// module docs), or `None` when the stack runs out.
#[inline(always)]
fn pop<const W: usize, T: TriangleTest, O: Observer>(s: &mut StreamScratch<W, T, O>) -> Option<WideChild> {
    while let Some(e) = s.stack.pop() {
        // Every ray of the list writes, and those that reach the child move on (no branch on a
        // test that differs from ray to ray).
        s.live.resize(e.len + 1, 0);
        let mut n = 0;
        for &it in &s.items[e.start..e.start + e.len] {
            let (r, t) = unpack(it);
            if O::ENABLED && s.active[r] {
                s.obs[r].backtrack(0, Backtrack::StackPop);
            }
            s.live[n] = r as u32;
            // An answered any-hit ray's interval ends at -inf: no entry reaches it.
            n += usize::from(t <= s.rays[r].interval.1);
        }
        s.live.truncate(n);
        s.items.truncate(e.start - 1);
        if !s.live.is_empty() {
            return Some(e.child);
        }
    }
    None
}
