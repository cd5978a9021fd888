use super::{cross, kd_leaf, scene_interval, Crossing, KdRoot, RestartPolicy, SHORT_STACK_MAX};
use crate::bvh2::NodeRef;
use crate::intersect::{KdRayContext, NoPair, TriangleTest};
use crate::kd::KdMemory;
use crate::method::Query;
use crate::observe::{Backtrack, Observer};
use crate::traverse::{begin, QueryState};
use crate::{Hit, Ray};

/// Rays per packet: four, as on the paper's GPU and in one SSE register.
pub const PACKET_WIDTH: usize = 4;

/// One entry of the packet's short stack: a node and every ray's segment and liveness there.
#[derive(Clone, Copy)]
struct Entry<const W: usize> {
    node: u32,
    t_min: [f32; W],
    t_max: [f32; W],
    live: [bool; W],
}

/// The packetized short-stack traversal (Horn et al. 2007, A.5) of up to `W` rays whose direction
/// components have the same signs (so they share the order of every node's children; callers
/// group rays by octant). Hits go to `hits`, events to each ray's own observer.
///
/// The packet descends where any live ray's segment goes, by the same tie rule as a single ray
/// ([`cross`]); each ray stays live only where its own segment goes, so it tests exactly the
/// leaves it would visit alone, in the same order, and stops at the same early exit. A.5 restarts
/// every ray from the previous leaf's exit; here each ray restarts from the exit of the last leaf
/// it was live in, which is what keeps restarts exact when rays go inactive.
pub fn trace_kd_packet<const W: usize, M: KdMemory + ?Sized, T: TriangleTest, O: Observer>(
    mem: &M,
    root: &KdRoot,
    rays: &[Ray],
    query: Query,
    policy: RestartPolicy,
    hits: &mut [Hit],
    obs: &mut [O],
) {
    let n = rays.len().min(W).min(hits.len()).min(obs.len());
    let RestartPolicy { push_down, short_stack: capacity } = policy;
    let capacity = capacity.min(SHORT_STACK_MAX);
    let mut ctx: [Option<KdRayContext<T>>; W] = core::array::from_fn(|_| None);
    let mut q: [QueryState; W] = core::array::from_fn(|i| QueryState::new(&rays[i.min(n.saturating_sub(1))], query));
    let (mut t_min, mut t_max, mut scene_max) = ([0.0f32; W], [0.0f32; W], [0.0f32; W]);
    let mut done = [true; W];
    for i in 0..n {
        if let Some((c, qi)) = begin::<T, NoPair>(&rays[i], root.scene_scale, query) {
            if let Some((a, b)) = scene_interval(&c, root) {
                (t_min[i], t_max[i], scene_max[i], done[i]) = (a, b, b, false);
                (ctx[i], q[i]) = (Some(c), qi);
            }
        }
    }
    let mut live = core::array::from_fn::<bool, W, _>(|i| !done[i]);
    // Where each ray resumes after a restart: the exit of the last leaf it was live in.
    let mut resume = t_min;
    let mut stack: [Entry<W>; SHORT_STACK_MAX] =
        [Entry { node: 0, t_min: [0.0; W], t_max: [0.0; W], live: [false; W] }; SHORT_STACK_MAX];
    let (mut len, mut node, mut restart_at, mut pushing) = (0usize, 0u32, 0u32, push_down);
    let mut budget = root.max_steps.saturating_mul(W as u32);
    while (0..n).any(|i| !done[i]) && budget > 0 {
        budget -= 1;
        let kd = mem.kd_node(node);
        // A popped entry may hold no ray that is still unfinished: go straight to the next one.
        let any_live = (0..n).any(|i| live[i]);
        if any_live && !kd.is_leaf() {
            let (mut want_first, mut want_second) = ([false; W], [false; W]);
            let mut split = [0.0f32; W];
            let (mut second_child, mut first_child) = (0, 0);
            for i in 0..n {
                let Some(c) = ctx[i].as_ref().filter(|_| live[i]) else { continue };
                obs[i].node(NodeRef::internal(node));
                match cross(&kd, &c.slab, t_min[i], t_max[i]) {
                    Crossing::First(f) => (want_first[i], first_child) = (true, f),
                    Crossing::Second(s) => (want_second[i], second_child) = (true, s),
                    Crossing::Both { first, second, t_split } => {
                        (want_first[i], want_second[i], split[i]) = (true, true, t_split);
                        (first_child, second_child) = (first, second);
                    }
                }
            }
            let (any_first, any_second) = (want_first.iter().any(|&w| w), want_second.iter().any(|&w| w));
            if !any_second {
                node = first_child;
                if pushing {
                    restart_at = node;
                }
            } else if !any_first {
                node = second_child;
                if pushing {
                    restart_at = node;
                }
            } else {
                pushing = false;
                let mut e = Entry { node: second_child, t_min, t_max, live: want_second };
                for i in 0..n {
                    if want_first[i] && want_second[i] {
                        e.t_min[i] = split[i];
                        t_max[i] = split[i];
                    }
                }
                if capacity > 0 {
                    if len == capacity {
                        stack.copy_within(1..len, 0);
                        len -= 1;
                    }
                    stack[len] = e;
                    len += 1;
                }
                live = want_first;
                node = first_child;
            }
            continue;
        }
        for i in 0..n {
            let Some(c) = ctx[i].as_ref().filter(|_| live[i] && kd.is_leaf()) else { continue };
            if kd_leaf(mem, node, &kd, t_max[i], c, &mut q[i], &mut obs[i]) || t_max[i] >= scene_max[i] {
                done[i] = true;
            }
            resume[i] = t_max[i];
        }
        if len > 0 {
            len -= 1;
            let e = stack[len];
            node = e.node;
            (t_min, t_max) = (e.t_min, e.t_max);
            for i in 0..n {
                live[i] = e.live[i] && !done[i];
                if live[i] {
                    obs[i].backtrack(0, Backtrack::StackPop);
                }
            }
            pushing = false;
            continue;
        }
        // Stack empty: restart every unfinished ray from where its last leaf ended.
        node = restart_at;
        pushing = push_down;
        for i in 0..n {
            live[i] = !done[i];
            if live[i] {
                (t_min[i], t_max[i]) = (resume[i], scene_max[i]);
                obs[i].backtrack(0, Backtrack::Restart);
            }
        }
    }
    for i in 0..n {
        hits[i] = q[i].hit();
    }
}
