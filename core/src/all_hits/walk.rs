//! The walk that finds every hit of a ray in a wide tree: Guthe's stack walk (hit children
//! nearest first) with the culling distance of a [`HitList`] instead of a closest hit, so that
//! every leaf a hit within the limit can lie in is visited, and each once.

use super::collect::HitList;
use super::AllHitsOptions;
use crate::intersect::{NoPair, TriangleTest, Watertight, BLOCK};
use crate::method::Query;
use crate::prepared::PreparedScene;
use crate::traverse::begin;
use crate::wide::traverse::{visiting_order, WideRoot};
use crate::wide::{ChildKernel, FastKernel, WideChild, WideMemory, WideTree};
use crate::{Hit, Ray};
use alloc::vec::Vec;

/// A postponed child: its slot words and the distance its box is entered at.
pub type Postponed = (u32, u32, f32);

/// Appends to `out` every hit of `ray` in `[tmin, tmax]` in a `W`-wide tree, in order of
/// `(t, prim)`, as `options` keep them; returns whether the list was cut at
/// [`AllHitsOptions::max_hits`]. `ray` is in the tree's frame (see [`all_hits_framed`] for a ray
/// as the caller gives it); `stack` is scratch space, reused across rays. A ray no method can
/// trace gets no hits.
pub fn all_hits<const W: usize, M: WideMemory<W> + ?Sized, T: TriangleTest>(
    mem: &M,
    root: WideRoot,
    ray: &Ray,
    options: &AllHitsOptions,
    out: &mut Vec<Hit>,
    stack: &mut Vec<Postponed>,
) -> bool {
    let Some((ctx, _)) = begin::<T, NoPair>(ray, root.scene_scale, Query::Closest) else { return false };
    let per_ray = ctx.tri();
    let mut list = HitList::new(out, options, ray.tmax);
    stack.clear();
    let mut next = Some(root.root);
    let mut budget = root.max_steps;
    while let Some(current) = next {
        if budget == 0 {
            // Never on an intact tree (each node is visited at most once); a list cut short by a
            // broken one says so.
            list.finish();
            return true;
        }
        budget -= 1;
        match current {
            WideChild::Node(index) => {
                let node = mem.wide_node(index);
                let (lo, hi) = ctx.box_interval(list.limit());
                let hits = FastKernel::test::<W>(&node, &ctx.slab, lo, hi);
                let mut order = [0u32; W];
                let n = visiting_order::<W, FastKernel>(&hits, false, &mut order);
                // Farthest first, so the nearest is popped next.
                for &slot in order[..n].iter().rev() {
                    let s = slot as usize % W;
                    stack.push((node.child[s], node.count[s], hits.t_enter[s]));
                }
            }
            WideChild::Leaf { first, count } => {
                let end = first + count;
                let mut pos = first;
                // Leaves start on a block boundary ([`crate::wide::WideBvh`]).
                while pos < end {
                    let block = mem.wide_block(pos / BLOCK as u32);
                    let hits = T::intersect_block(&per_ray, &block, ctx.ray.tmin, list.limit());
                    let n = (end - pos).min(BLOCK as u32);
                    let mut live = hits.mask & ((1 << n) - 1);
                    while live != 0 {
                        let lane = live.trailing_zeros() as usize;
                        let prim = mem.prim(pos + lane as u32);
                        list.offer(Hit { t: hits.t[lane], prim, u: hits.u[lane], v: hits.v[lane] });
                        live &= live - 1;
                    }
                    pos += n;
                }
            }
        }
        next = None;
        while let Some((child, count, t_enter)) = stack.pop() {
            // A box entered beyond the limit by more than the slack holds no hit to keep.
            if t_enter <= list.limit() + ctx.t_slack {
                next = WideChild::from_words(child, count);
                if next.is_some() {
                    break;
                }
            }
        }
    }
    list.finish()
}

/// [`all_hits`] of a ray as the caller gives it, in `scene` ([`PreparedScene::query_tree`]), with the
/// watertight test: the ray framed as every backend frames a batch
/// ([`PreparedScene::frame_rays`]) and its hits put back in the caller's frame. A ray that no
/// method can answer exactly gets one hit, [`Hit::REFUSED`], as a closest-hit query answers it.
pub fn all_hits_framed(
    scene: &PreparedScene,
    tree: (WideTree<'_>, WideRoot),
    ray: &Ray,
    options: &AllHitsOptions,
    out: &mut Vec<Hit>,
    stack: &mut Vec<Postponed>,
) -> bool {
    let framed = scene.frame_rays(core::slice::from_ref(ray));
    let mut probe = [Hit::MISS];
    if framed.finish(&mut probe) == 1 {
        out.push(Hit::REFUSED);
        return false;
    }
    let start = out.len();
    let (tree, root) = tree;
    let r = &framed.rays()[0];
    let truncated = match tree {
        WideTree::Four(t) => all_hits::<4, _, Watertight>(&t.memory(), root, r, options, out, stack),
        WideTree::Eight(t) => all_hits::<8, _, Watertight>(&t.memory(), root, r, options, out, stack),
    };
    if framed.changed() {
        // Each `t` back in the caller's frame. The order stays that of the scene's frame, where
        // the closest hit is decided: where moving a far ray back rounds two distances to one
        // value, the list keeps the nearer in the scene's frame first, as the closest hit does.
        for h in &mut out[start..] {
            framed.finish(core::slice::from_mut(h));
        }
    }
    truncated
}
