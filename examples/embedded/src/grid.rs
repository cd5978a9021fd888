//! The self-test grid traced with every method, summarized as counts and a digest that a host and
//! a device must agree on bit for bit.

use crate::{self_test_ray, FlashScene, Method, Query, METHODS, SELF_TEST_RAYS};
use core::fmt;
use raytrail_core::observe::Counters;

/// 64-bit FNV-1a, word by word: small, no tables, the same on every target.
#[derive(Clone, Copy, Debug)]
struct Fnv(u64);

impl Fnv {
    const START: Fnv = Fnv(0xcbf2_9ce4_8422_2325);

    fn word(self, w: u64) -> Fnv {
        let mut h = self.0;
        for b in w.to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
        Fnv(h)
    }
}

/// One method over the grid: how many rays hit (closest hit) and are occluded (any hit), the work
/// it did (both queries together), and a digest of every answer and every counter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MethodTally {
    /// The method.
    pub method: Method,
    /// Rays whose closest-hit query found a hit.
    pub hits: u32,
    /// Rays whose any-hit query found a hit.
    pub occluded: u32,
    /// Work counters over both queries of every ray.
    pub counters: Counters,
    /// FNV-1a over each ray's closest hit (primitive, `t`, `u`, `v` as bits) and occlusion, then
    /// the counters.
    pub digest: u64,
}

impl MethodTally {
    /// Traces the grid with `method`; `None` if the method's tables are not baked.
    pub fn trace(scene: &FlashScene, method: Method) -> Option<MethodTally> {
        let mut c = Counters::default();
        let (mut hits, mut occluded, mut h) = (0, 0, Fnv::START);
        for i in 0..SELF_TEST_RAYS {
            let ray = self_test_ray(i);
            let closest = scene.trace_method(&ray, method, Query::Closest, &mut c)?;
            let any = scene.trace_method(&ray, method, Query::Any, &mut c)?.is_hit();
            hits += closest.is_hit() as u32;
            occluded += any as u32;
            h = h.word(u64::from(closest.prim) << 32 | u64::from(closest.t.to_bits()));
            h = h.word(u64::from(closest.u.to_bits()) << 32 | u64::from(closest.v.to_bits()));
            h = h.word(any as u64);
        }
        c.rays = 2 * u64::from(SELF_TEST_RAYS);
        let words = [c.rays, c.internal_nodes, c.leaves, c.primitive_tests, c.backtracks, c.stack_pops];
        let more = [c.iterative, c.link_reads, c.restarts, c.hash[0], c.hash[1]];
        for w in words.into_iter().chain(more).chain(c.register).chain(c.levels) {
            h = h.word(w);
        }
        Some(MethodTally { method, hits, occluded, counters: c, digest: h.0 })
    }
}

/// One line, the same on host and device: `method NAME hits H occluded O nodes N leaves L tests T
/// backtracks B digest D`.
impl fmt::Display for MethodTally {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = &self.counters;
        write!(
            f,
            "method {} hits {} occluded {} nodes {} leaves {} tests {} backtracks {} digest {:016x}",
            self.method.name(),
            self.hits,
            self.occluded,
            c.internal_nodes,
            c.leaves,
            c.primitive_tests,
            c.backtracks,
            self.digest
        )
    }
}

/// Every method of [`METHODS`] over the grid, and one digest over all of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GridReport {
    /// One tally per method, in the order of [`METHODS`].
    pub tallies: [MethodTally; METHODS.len()],
    /// FNV-1a over the tallies' digests.
    pub digest: u64,
}

impl GridReport {
    /// Combines tallies (in the order of [`METHODS`]) into a report.
    pub fn of(tallies: [MethodTally; METHODS.len()]) -> GridReport {
        let digest = tallies.iter().fold(Fnv::START, |h, t| h.word(t.digest)).0;
        GridReport { tallies, digest }
    }
}

/// The tallies one per line, then `grid digest D`.
impl fmt::Display for GridReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for t in &self.tallies {
            writeln!(f, "{t}")?;
        }
        write!(f, "grid digest {:016x}", self.digest)
    }
}

/// Traces the grid with every method; `None` if the tables do not validate.
pub fn grid_report() -> Option<GridReport> {
    let scene = FlashScene::load().ok()?;
    let mut tallies = [MethodTally::trace(&scene, METHODS[0])?; METHODS.len()];
    for (t, &m) in tallies.iter_mut().zip(&METHODS).skip(1) {
        *t = MethodTally::trace(&scene, m)?;
    }
    Some(GridReport::of(tallies))
}
