//! Every hit along each ray on the device ([`Trace::all_hits`]): the wide stack walk with a hit
//! list per ray for an answer (shaders/all_hits.wgsl), on the tree the core's all-hits walk reads,
//! the lists read back from the rays' record slots and put back in the caller's frame as the core
//! puts them ([`raytrail_core::all_hits::all_hits_framed`]).
//!
//! A slot holds [`FIRST_SLOT_HITS`] hits on the first trace. A ray whose list fills its slot while
//! the caller's limit allows more may have lost hits: it is traced again with a slot four times as
//! large, until no list fills its slot. A list never holds more hits than the tree has triangle
//! references, so a slot one larger than that is never filled, and the rounds end.
//!
//! [`Trace::all_hits`]: raytrail_core::trace::Trace::all_hits

use crate::compose::Answer;
use crate::device::device_error;
use crate::scene::WgpuScene;
use crate::wide_query::query_method;
use crate::WgpuBackend;
use raytrail_core::all_hits::{AllHits, AllHitsOptions};
use raytrail_core::method::WideMethod;
use raytrail_core::wide::WideTree;
use raytrail_core::{Error, Hit, Ray};

/// Hits a ray's slot holds on the first trace: a ray crosses a closed mesh an even number of
/// times, and most rays of a scene cross few surfaces.
const FIRST_SLOT_HITS: usize = 8;

/// Rays traced and read back at once: their slots on the host stay within a few megabytes
/// (132 bytes a ray at the first slot size).
const CHUNK_RAYS: usize = 1 << 16;

/// The top bit of a slot's first word: the ray's walk ran out of steps (shaders/all_hits.wgsl);
/// the other bits count the hits held.
const UNFINISHED_BIT: u32 = 1 << 31;

impl WgpuBackend {
    /// [`Trace::all_hits`](raytrail_core::trace::Trace::all_hits) on the device.
    pub(crate) fn trace_all_hits(
        &self,
        scene: &WgpuScene,
        rays: &[Ray],
        options: &AllHitsOptions,
    ) -> Result<AllHits, Error> {
        let prepared = &scene.prepared;
        let method = query_method(prepared)?;
        let references = match prepared.wide_tree(method)? {
            WideTree::Four(t) => t.triangles().len(),
            WideTree::Eight(t) => t.triangles().len(),
        };
        // The list keeps the caller's limit and one more, whose presence says it was cut.
        let keep = options.max_hits.saturating_add(1);
        let lists = Lists { method, keep, largest_slot: keep.min(references + 1), merge: options.merge_equal_t };
        let framed = prepared.frame_rays(rays);
        let mut out = AllHits::default();
        for (c, chunk) in framed.rays().chunks(CHUNK_RAYS).enumerate() {
            let base = c * CHUNK_RAYS;
            for (k, (mut list, unfinished)) in self.lists(scene, &lists, chunk)?.into_iter().enumerate() {
                let mut probe = Hit::MISS;
                if framed.finish_ray(base + k, &mut probe) {
                    out.push(&[Hit::REFUSED], false);
                    continue;
                }
                // A walk the step budget ended (a broken tree) says its list is cut, as the CPU's.
                let truncated = unfinished || list.len() > options.max_hits;
                list.truncate(options.max_hits);
                for hit in &mut list {
                    framed.finish_ray(base + k, hit);
                }
                out.push(&list, truncated);
            }
        }
        Ok(out)
    }

    /// The lists of `rays` (in the scene's frame), each of up to `lists.keep` hits, in order, and
    /// whether each ray's walk ran out of steps.
    fn lists(&self, scene: &WgpuScene, lists: &Lists, rays: &[Ray]) -> Result<Vec<(Vec<Hit>, bool)>, Error> {
        let mut out = vec![(Vec::new(), false); rays.len()];
        let mut todo: Vec<usize> = (0..rays.len()).collect();
        let mut slot = FIRST_SLOT_HITS.min(lists.largest_slot);
        loop {
            let traced: Vec<Ray> = todo.iter().map(|&i| rays[i]).collect();
            let records = self.trace_lists(scene, lists, &traced, slot)?;
            let stride = 1 + 4 * slot;
            let mut again = Vec::new();
            for (k, &i) in todo.iter().enumerate() {
                let words = &records[k * stride..(k + 1) * stride];
                let (held, unfinished) = ((words[0] & !UNFINISHED_BIT) as usize, words[0] & UNFINISHED_BIT != 0);
                if held > slot {
                    return Err(device_error(format!("ray {i}'s hit list holds {held} hits in a slot of {slot}")));
                }
                if held == slot && slot < lists.largest_slot {
                    again.push(i);
                    continue;
                }
                let found = words[1..1 + 4 * held]
                    .chunks_exact(4)
                    .map(|w| Hit {
                        t: f32::from_bits(w[0]),
                        prim: w[1],
                        u: f32::from_bits(w[2]),
                        v: f32::from_bits(w[3]),
                    })
                    .collect();
                out[i] = (found, unfinished);
            }
            if again.is_empty() {
                return Ok(out);
            }
            todo = again;
            slot = slot.saturating_mul(4).min(lists.largest_slot);
        }
    }

    /// Traces `rays` with slots of `slot` hits; returns every ray's slot, in ray order.
    fn trace_lists(&self, scene: &WgpuScene, lists: &Lists, rays: &[Ray], slot: usize) -> Result<Vec<u32>, Error> {
        let (_, records) = self.run_wide_query(scene, lists.method, Answer::AllHits, rays, 1 + 4 * slot, |p| {
            p.record_cap = slot.min(u32::MAX as usize) as u32;
            p.all_hits_keep = lists.keep.min(u32::MAX as usize) as u32;
            p.all_hits_merge = u32::from(lists.merge);
        })?;
        Ok(records)
    }
}

/// What every trace of one all-hits call shares.
struct Lists {
    /// The method whose tree is walked.
    method: WideMethod,
    /// Hits a list keeps: the caller's limit and one more.
    keep: usize,
    /// The largest slot a ray needs: the keep, or one more than the tree's triangle references.
    largest_slot: usize,
    /// Whether hits at one `t` count once.
    merge: bool,
}
