//! How rays are grouped into packets: one convention for every backend and every packet method
//! (kd packets of [`crate::kd::traverse::PACKET_WIDTH`] rays, wide packets of
//! [`WIDE_PACKET`](crate::wide::packet::WIDE_PACKET)), so that a ray shares its packet with the
//! same rays everywhere and per-ray counters and enumerations agree (a packet's nodes depend on
//! its rays).
//!
//! A batch is cut into spans of [`GROUPING_RAYS`] rays; in each, rays are stably grouped by
//! direction octant ([`octant`]) in octant order, and each octant's run is cut into packets of at
//! most the packet width. Packets never cross two spans, so a backend may trace spans in
//! parallel.

#[cfg(feature = "alloc")]
use crate::kd::traverse::PACKET_WIDTH;
use crate::Ray;
#[cfg(feature = "alloc")]
use alloc::vec::Vec;

/// Rays per grouping span: packets are formed within consecutive spans of this many rays of a
/// batch and never across two, so a backend may trace spans (or multiples of them) in parallel.
pub const GROUPING_RAYS: usize = 256;

/// A slot of [`packet_slots`] that holds no ray.
pub const PADDING: u32 = u32::MAX;

/// The direction's octant: bit `k` set where component `k` has its sign bit set (`-0` counts as
/// negative, as the traversals order children by the sign bit).
#[inline]
pub fn octant(ray: &Ray) -> usize {
    (ray.dir[0].is_sign_negative() as usize)
        | (ray.dir[1].is_sign_negative() as usize) << 1
        | (ray.dir[2].is_sign_negative() as usize) << 2
}

/// Calls `packet` with the rays of each packet of one chunk (at most [`GROUPING_RAYS`] rays; the
/// rest is ignored), as indices into `chunk`, in packet order: each octant's rays in chunk order,
/// cut into runs of at most `width` (at least 1). Needs no allocation: a counting sort by octant.
/// Inlined, so that `packet` compiles as its caller does (for a vector extension, say).
#[inline(always)]
pub fn for_each_packet(chunk: &[Ray], width: usize, mut packet: impl FnMut(&[u16])) {
    let chunk = &chunk[..chunk.len().min(GROUPING_RAYS)];
    let mut start = [0usize; 9];
    for r in chunk {
        start[octant(r) + 1] += 1;
    }
    for o in 0..8 {
        start[o + 1] += start[o];
    }
    let mut order = [0u16; GROUPING_RAYS];
    let mut at = start;
    for (i, r) in chunk.iter().enumerate() {
        let o = octant(r);
        order[at[o]] = i as u16;
        at[o] += 1;
    }
    for o in 0..8 {
        for p in order[start[o]..start[o + 1]].chunks(width.max(1)) {
            packet(p);
        }
    }
}

/// The packets of a batch as slots, `width` per packet: for each slot, the index of the ray it
/// holds or [`PADDING`]. Slot `width * p + k` is ray `k` of packet `p`; padding only ends a packet.
#[cfg(feature = "alloc")]
pub fn packet_slots_of(rays: &[Ray], width: usize) -> Vec<u32> {
    let width = width.max(1);
    let mut out = Vec::with_capacity(rays.len() + rays.len().div_ceil(GROUPING_RAYS) * 8 * (width - 1));
    for (c, chunk) in rays.chunks(GROUPING_RAYS).enumerate() {
        for_each_packet(chunk, width, |p| {
            out.extend(p.iter().map(|&i| (c * GROUPING_RAYS) as u32 + u32::from(i)));
            out.extend(core::iter::repeat_n(PADDING, width - p.len()));
        });
    }
    out
}

/// The kd packets of a batch as slots ([`packet_slots_of`] with [`PACKET_WIDTH`]).
#[cfg(feature = "alloc")]
pub fn packet_slots(rays: &[Ray]) -> Vec<u32> {
    packet_slots_of(rays, PACKET_WIDTH)
}

/// The kd packets of a batch as lists of ray indices (the slots of [`packet_slots`] without padding).
#[cfg(feature = "alloc")]
pub fn packets(rays: &[Ray]) -> Vec<Vec<u32>> {
    packet_slots(rays).chunks(PACKET_WIDTH).map(|p| p.iter().copied().filter(|&i| i != PADDING).collect()).collect()
}

#[cfg(all(test, feature = "alloc"))]
mod tests {
    use super::*;

    fn ray(dir: [f32; 3]) -> Ray {
        Ray { origin: [0.0; 3], tmin: 0.0, dir, tmax: f32::INFINITY }
    }

    /// Rays over every octant, with signed zeros, in a scrambled order, over three chunks.
    fn mixed() -> Vec<Ray> {
        let s = [1.0, -1.0, 0.0, -0.0, 0.5, -2.0];
        (0..(2 * GROUPING_RAYS + 67) as u32)
            .map(|i| {
                let k = (i as usize * 7) % 216;
                ray([s[k % 6], s[(k / 6) % 6], s[k / 36]])
            })
            .collect()
    }

    /// The grouping written out the slow way: per chunk, a stable sort by octant, then runs of at
    /// most four rays of one octant.
    fn by_sorting(rays: &[Ray]) -> Vec<Vec<u32>> {
        let mut packets = Vec::new();
        for (c, chunk) in rays.chunks(GROUPING_RAYS).enumerate() {
            let mut order: Vec<u32> = (0..chunk.len() as u32).collect();
            order.sort_by_key(|&i| octant(&chunk[i as usize]));
            for run in order.chunk_by(|&a, &b| octant(&chunk[a as usize]) == octant(&chunk[b as usize])) {
                for p in run.chunks(PACKET_WIDTH) {
                    packets.push(p.iter().map(|&i| (c * GROUPING_RAYS) as u32 + i).collect());
                }
            }
        }
        packets
    }

    #[test]
    fn packets_are_the_stable_octant_sort_cut_into_fours() {
        let rays = mixed();
        assert_eq!(packet_slots(&rays).len() % PACKET_WIDTH, 0);
        assert_eq!(packets(&rays), by_sorting(&rays));
    }

    #[test]
    fn every_ray_appears_once_and_padding_only_ends_a_packet_of_one_octant() {
        let rays = mixed();
        let slots = packet_slots(&rays);
        let mut seen: Vec<u32> = slots.iter().copied().filter(|&i| i != PADDING).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..rays.len() as u32).collect::<Vec<_>>());
        for p in slots.chunks(PACKET_WIDTH) {
            let real: Vec<u32> = p.iter().copied().take_while(|&i| i != PADDING).collect();
            assert!(!real.is_empty(), "a packet of padding only");
            assert!(p[real.len()..].iter().all(|&i| i == PADDING), "padding before a ray: {p:?}");
            assert!(real.iter().all(|&i| octant(&rays[i as usize]) == octant(&rays[real[0] as usize])));
        }
    }

    /// Any width: the stable octant sort cut into runs of at most `width`, padded to `width`.
    #[test]
    fn every_width_groups_as_the_octant_sort_does() {
        let rays = mixed();
        for width in [1, 3, 32] {
            let slots = packet_slots_of(&rays, width);
            assert_eq!(slots.len() % width, 0);
            let mut want = Vec::new();
            for (c, chunk) in rays.chunks(GROUPING_RAYS).enumerate() {
                let mut order: Vec<u32> = (0..chunk.len() as u32).collect();
                order.sort_by_key(|&i| octant(&chunk[i as usize]));
                for run in order.chunk_by(|&a, &b| octant(&chunk[a as usize]) == octant(&chunk[b as usize])) {
                    for p in run.chunks(width) {
                        want.extend(p.iter().map(|&i| (c * GROUPING_RAYS) as u32 + i));
                        want.extend(core::iter::repeat_n(PADDING, width - p.len()));
                    }
                }
            }
            assert_eq!(slots, want, "width {width}");
        }
    }

    #[test]
    fn packets_never_span_two_chunks() {
        for p in packets(&mixed()) {
            assert!(p.iter().all(|&i| i as usize / GROUPING_RAYS == p[0] as usize / GROUPING_RAYS), "{p:?}");
        }
    }

    #[test]
    fn order_is_kept_within_an_octant_and_signed_zero_is_its_own_octant() {
        let rays = [ray([1.0, 1.0, 1.0]), ray([-0.0, 1.0, 1.0]), ray([0.0, 2.0, 1.0]), ray([-1.0, 0.0, 3.0])];
        assert_eq!(packet_slots(&rays), [0, 2, PADDING, PADDING, 1, 3, PADDING, PADDING]);
        assert_eq!(packet_slots(&[ray([-1.0, -1.0, -1.0]); 8]), (0..8).collect::<Vec<_>>());
        assert!(packet_slots(&[]).is_empty());
    }
}
