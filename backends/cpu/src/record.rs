//! The one place a chunk's loop is chosen for what a trace records (nothing, counters, or each
//! ray's enumeration in canonical node ids) and for its triangle test, whatever the structure.

use crate::chunk::Chunk;
use raytrail_core::intersect::{MollerTrumbore, TriangleTest, Watertight};
use raytrail_core::method::Method;
use raytrail_core::observe::{Both, Counters, NoObserver, Observer, Recorder};
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Record, TriangleTestKind};
use raytrail_core::{Error, Hit, Ray};

/// A loop over rays traced independently: one observer may watch a whole slice, and a slice set
/// up once (a stack, say) serves all its rays.
pub(crate) trait RayLoop {
    /// Traces `rays` into `hits`, reporting every ray's events to `obs`.
    fn trace<O: Observer>(&self, rays: &[Ray], hits: &mut [Hit], obs: &mut O);
}

/// A loop over rays that share walks of the tree (packets, streams): each ray's observer comes
/// back from the walk.
pub(crate) trait SharedWalks {
    /// Traces `rays` into `hits`, handing each ray's index and observer to `done`.
    fn trace<O: Observer + Default>(&self, rays: &[Ray], hits: &mut [Hit], done: &mut impl FnMut(usize, O));
}

/// An observer whose per-ray instances add up to the chunk's.
trait Summed: Observer + Default {
    /// Adds one ray's observations.
    fn absorb(&mut self, ray: Self);
}

impl Summed for NoObserver {
    #[inline(always)]
    fn absorb(&mut self, _: Self) {}
}

impl Summed for Counters {
    #[inline(always)]
    fn absorb(&mut self, ray: Self) {
        self.add(&ray);
    }
}

/// A chunk's loop in the two forms [`record`] asks for.
pub(crate) trait ChunkLoop {
    /// Traces `rays` into `hits`, all observed by `obs`.
    #[allow(private_bounds)]
    fn trace_all<O: Summed>(&self, rays: &[Ray], hits: &mut [Hit], obs: &mut O);
    /// Traces `rays` into `hits`, each ray with a fresh observer handed with its index to `done`.
    fn trace_each<O: Observer + Default>(&self, rays: &[Ray], hits: &mut [Hit], done: &mut impl FnMut(usize, O));
}

/// A [`RayLoop`] as a [`ChunkLoop`]: the whole slice in one call, or each ray as a slice of one.
pub(crate) struct Independent<'a, L>(pub &'a L);

impl<L: RayLoop> ChunkLoop for Independent<'_, L> {
    #[inline(always)]
    #[allow(private_bounds)]
    fn trace_all<O: Summed>(&self, rays: &[Ray], hits: &mut [Hit], obs: &mut O) {
        self.0.trace(rays, hits, obs);
    }
    fn trace_each<O: Observer + Default>(&self, rays: &[Ray], hits: &mut [Hit], done: &mut impl FnMut(usize, O)) {
        for (i, (ray, hit)) in rays.iter().zip(hits.iter_mut()).enumerate() {
            let mut obs = O::default();
            self.0.trace(core::slice::from_ref(ray), core::slice::from_mut(hit), &mut obs);
            done(i, obs);
        }
    }
}

/// A [`SharedWalks`] as a [`ChunkLoop`]: the rays' observers summed, or handed on.
pub(crate) struct Shared<'a, S>(pub &'a S);

impl<S: SharedWalks> ChunkLoop for Shared<'_, S> {
    #[inline(always)]
    #[allow(private_bounds)]
    fn trace_all<O: Summed>(&self, rays: &[Ray], hits: &mut [Hit], obs: &mut O) {
        self.0.trace::<O>(rays, hits, &mut |_, ray| obs.absorb(ray));
    }
    #[inline(always)]
    fn trace_each<O: Observer + Default>(&self, rays: &[Ray], hits: &mut [Hit], done: &mut impl FnMut(usize, O)) {
        self.0.trace(rays, hits, done);
    }
}

/// Traces `chunk` with `walk`, observing what `record` asks for; `method` names the structure
/// whose node ids an enumeration is made canonical in. Returns the chunk's counters (only `rays`
/// is set when nothing is recorded).
pub(crate) fn record(
    scene: &PreparedScene,
    method: Method,
    record: Record,
    chunk: Chunk<'_>,
    walk: &impl ChunkLoop,
) -> Result<Counters, Error> {
    let mut counters = Counters::default();
    match record {
        Record::Nothing => walk.trace_all(chunk.rays, chunk.hits, &mut NoObserver),
        Record::Counters => walk.trace_all(chunk.rays, chunk.hits, &mut counters),
        Record::Enumerations => {
            let mut failed = None;
            let slots = &mut *chunk.enumerations;
            walk.trace_each::<Both<Counters, Recorder>>(chunk.rays, chunk.hits, &mut |i, o| {
                counters.add(&o.0);
                match scene.canonical_ids(method, o.1.nodes.iter().copied()) {
                    Ok(ids) => slots[i] = ids,
                    Err(e) => {
                        failed.get_or_insert(e);
                    }
                }
            });
            if let Some(e) = failed {
                return Err(e);
            }
        }
    }
    counters.rays = chunk.rays.len() as u64;
    Ok(counters)
}

/// Code generic over the triangle test, to be run with the one a trace asked for.
pub(crate) trait WithTest {
    /// What the code returns.
    type Output;
    /// Runs the code with test `T`.
    fn with<T: TriangleTest>(self) -> Self::Output;
}

/// Runs `code` with the triangle test `kind` names: the one match on it in the backend.
#[inline(always)]
pub(crate) fn with_test<C: WithTest>(kind: TriangleTestKind, code: C) -> C::Output {
    match kind {
        TriangleTestKind::Watertight => code.with::<Watertight>(),
        TriangleTestKind::MollerTrumbore => code.with::<MollerTrumbore>(),
    }
}
