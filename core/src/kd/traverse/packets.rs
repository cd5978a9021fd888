//! How rays are grouped into kd packets: one convention for every backend, so that a ray shares
//! its packet with the same rays everywhere and per-ray counters agree (a packet's internal nodes,
//! pops and restarts depend on its rays; its leaves do not).
//!
//! A batch is cut into chunks of [`PACKET_CHUNK`] rays; in each, rays are stably grouped by
//! direction octant ([`octant`]) in octant order, and each octant's run is cut into packets of at
//! most [`PACKET_WIDTH`] rays. Packets never span two chunks, so a backend may trace chunks in
//! parallel.

#[cfg(feature = "alloc")]
use super::PACKET_WIDTH;
use crate::Ray;
#[cfg(feature = "alloc")]
use alloc::vec::Vec;

/// Rays per chunk of the packet grouping (a CPU backend's natural task size).
pub const PACKET_CHUNK: usize = 256;

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

/// The packets of a batch as slots: for each slot, the index of the ray it holds or [`PADDING`].
/// Slot `PACKET_WIDTH * p + k` is ray `k` of packet `p`; every packet but its rays is padding, and
/// padding only ends a packet.
#[cfg(feature = "alloc")]
pub fn packet_slots(rays: &[Ray]) -> Vec<u32> {
    let mut out = Vec::with_capacity(rays.len() + rays.len().div_ceil(PACKET_CHUNK) * 8 * (PACKET_WIDTH - 1));
    let mut groups: [Vec<u32>; 8] = Default::default();
    for (c, chunk) in rays.chunks(PACKET_CHUNK).enumerate() {
        for (i, r) in chunk.iter().enumerate() {
            groups[octant(r)].push((c * PACKET_CHUNK + i) as u32);
        }
        for g in &mut groups {
            let pad = g.len().next_multiple_of(PACKET_WIDTH) - g.len();
            out.append(g);
            out.extend(core::iter::repeat_n(PADDING, pad));
        }
    }
    out
}

/// The packets of a batch as lists of ray indices (the slots of [`packet_slots`] without padding).
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
        (0..(2 * PACKET_CHUNK + 67) as u32)
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
        for (c, chunk) in rays.chunks(PACKET_CHUNK).enumerate() {
            let mut order: Vec<u32> = (0..chunk.len() as u32).collect();
            order.sort_by_key(|&i| octant(&chunk[i as usize]));
            for run in order.chunk_by(|&a, &b| octant(&chunk[a as usize]) == octant(&chunk[b as usize])) {
                for p in run.chunks(PACKET_WIDTH) {
                    packets.push(p.iter().map(|&i| (c * PACKET_CHUNK) as u32 + i).collect());
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

    #[test]
    fn packets_never_span_two_chunks() {
        for p in packets(&mixed()) {
            assert!(p.iter().all(|&i| i as usize / PACKET_CHUNK == p[0] as usize / PACKET_CHUNK), "{p:?}");
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
