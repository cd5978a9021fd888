//! Trail lanes: the core's stackless wide walk ([`WideTrailState`], `bvh4-hash`) over a
//! [`CountingWideMemory`] of the 4-wide tree and its hash over node keys, with the
//! [`FastKernel`] the CPU backend traces with.

use crate::memory::{CountingWideMemory, Table, Traffic};
use crate::sim::{drive, LaneObserver, MethodRun, SimConfig};
use crate::stepper::{Outcome, Stepper};
use crate::wide_lanes::hit_children;
use raytrail_core::hash::lookup_in;
use raytrail_core::intersect::{NoPair, Watertight};
use raytrail_core::key::{Key, KeyWidth};
use raytrail_core::method::{Query, WideMethod};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::traverse::{begin, Machine, QueryState};
use raytrail_core::wide::keyed::{WideHashedMemory, WideKeyedMemory};
use raytrail_core::wide::trail::WideTrailState;
use raytrail_core::wide::traverse::{WideRayContext, WideRoot};
use raytrail_core::wide::{FastKernel, WideMemory};
use raytrail_core::{Error, Ray};
use std::marker::PhantomData;

/// The hash over node keys, read through the counter: a displacement entry, and a cell unless
/// the entry held the node.
impl<const W: usize, M: WideMemory<W>> WideKeyedMemory<W> for CountingWideMemory<WideHashedMemory<'_, M>> {
    fn keyed_node<K: Key>(&self, key: K) -> (u32, bool) {
        let tables = self.inner();
        let displacement = |i: u32| {
            self.tally().touch(Table::Displacement, i, 4);
            tables.displacement.get(i as usize).copied().unwrap_or(0)
        };
        let cell = |i: u32| {
            self.tally().touch(Table::HashCells, i, 4);
            tables.cells.get(i as usize).copied().unwrap_or(0)
        };
        let (node, direct) = lookup_in(displacement, cell, tables.shape, key);
        (node.index(), direct)
    }
}

/// Simulates the trail walk `m` with the key width its tree needs.
pub(crate) fn simulate_trail(
    prepared: &PreparedScene,
    m: WideMethod,
    rays: &[Ray],
    cfg: &SimConfig,
) -> Result<MethodRun, Error> {
    let root = prepared.wide_root(m)?;
    let (mem, keys) = prepared.wide_keyed(m)?;
    let mem = CountingWideMemory::new(mem);
    Ok(match keys {
        KeyWidth::W32 => drive(&TrailLanes::<4, u32, _> { mem, root, query: cfg.query, key: PhantomData }, rays, cfg),
        KeyWidth::W64 => drive(&TrailLanes::<4, u64, _> { mem, root, query: cfg.query, key: PhantomData }, rays, cfg),
    })
}

/// Lanes of the trail walk over a `W`-wide tree with keys `K`.
struct TrailLanes<const W: usize, K, M> {
    mem: CountingWideMemory<M>,
    root: WideRoot,
    query: Query,
    key: PhantomData<K>,
}

impl<const W: usize, K: Key, M: WideMemory<W>> Stepper for TrailLanes<W, K, WideHashedMemory<'_, M>> {
    type Lane = (WideTrailState<W, K, FastKernel>, WideRayContext<Watertight>);

    fn begin(&self, ray: &Ray) -> Option<Self::Lane> {
        // As `trace_wide_trail_batch`: a ray `begin` turns away visits nothing.
        let (ctx, _) = begin::<Watertight, NoPair>(ray, self.root.scene_scale, self.query)?;
        Some((WideTrailState::new(self.root.root), ctx))
    }

    fn step(&self, (state, ctx): &mut Self::Lane, q: &mut QueryState, obs: &mut LaneObserver) -> Outcome {
        let limit = q.limit();
        let hash_reads = self.mem.hash_reads();
        let step = state.step(&self.mem, ctx, q, obs);
        // A node that leaves siblings to visit writes itself into the register (no stack).
        let postponed = u32::from(hit_children::<W, _>(self.mem.inner(), obs, ctx, limit) > 1);
        // The node (or leaf) from its parent's slot, then each hash read of a backtrack after
        // the one before: a lookup is a displacement entry and, unless it held the node, a cell.
        let rounds = 1 + (self.mem.hash_reads() - hash_reads) as u32;
        Outcome { step, resumed: false, postponed, pushed: 0, dropped: 0, rounds }
    }

    fn max_steps(&self) -> u32 {
        self.root.max_steps
    }

    fn stack_entry_bytes(&self) -> u64 {
        0
    }

    fn end_cycle(&self) -> u64 {
        self.mem.tally().end_cycle()
    }

    fn traffic(&self) -> Traffic {
        self.mem.tally().traffic()
    }
}
