//! Packing rays into packets of one direction octant for the kd-packet kernel.
//!
//! The packets are the CPU backend's (`backends/cpu/src/dispatch_kd.rs`), so that every ray shares
//! its packet with the same rays on both backends and the per-ray counters agree (a packet's
//! internal nodes, pops and restarts depend on its rays; its leaves do not): the batch is cut into
//! the CPU's chunks of [`CPU_CHUNK`] rays; in each, rays are stably sorted by octant, then cut into
//! runs of at most four rays of one octant. Here every run is padded to four slots, so that packet
//! `p` of the kernel is slots `4p .. 4p + 3`.

use raytrail_core::kd::traverse::PACKET_WIDTH;
use raytrail_core::Ray;

/// Rays per task of the CPU backend (`CHUNK` in backends/cpu/src/backend.rs): its packets never
/// span two chunks.
const CPU_CHUNK: usize = 256;

/// The direction's octant: bit `k` set where component `k` has its sign bit set (`-0` counts as
/// negative), as the CPU groups packets.
fn octant(r: &Ray) -> usize {
    (r.dir[0].is_sign_negative() as usize)
        | (r.dir[1].is_sign_negative() as usize) << 1
        | (r.dir[2].is_sign_negative() as usize) << 2
}

/// For each slot of the padded batch, the index of the ray it holds, or `u32::MAX` for padding:
/// chunk by chunk, rays grouped by octant in octant order, keeping their order within an octant,
/// each octant padded to a multiple of [`PACKET_WIDTH`].
pub(crate) fn packet_order(rays: &[Ray]) -> Vec<u32> {
    let mut out = Vec::with_capacity(rays.len() + rays.len().div_ceil(CPU_CHUNK) * 8 * (PACKET_WIDTH - 1));
    let mut groups: [Vec<u32>; 8] = Default::default();
    for (c, chunk) in rays.chunks(CPU_CHUNK).enumerate() {
        for (i, r) in chunk.iter().enumerate() {
            groups[octant(r)].push((c * CPU_CHUNK + i) as u32);
        }
        for g in &mut groups {
            let pad = g.len().next_multiple_of(PACKET_WIDTH) - g.len();
            out.append(g);
            out.extend(std::iter::repeat_n(u32::MAX, pad));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(dir: [f32; 3]) -> Ray {
        Ray { origin: [0.0; 3], tmin: 0.0, dir, tmax: f32::INFINITY }
    }

    /// The CPU backend's packets (backend.rs's chunks, dispatch_kd.rs's packets), as lists of ray
    /// indices.
    fn cpu_packets(rays: &[Ray]) -> Vec<Vec<u32>> {
        let mut packets = Vec::new();
        for (c, chunk) in rays.chunks(CPU_CHUNK).enumerate() {
            let mut order: Vec<u32> = (0..chunk.len() as u32).collect();
            order.sort_by_key(|&i| octant(&chunk[i as usize]));
            let mut start = 0;
            while start < order.len() {
                let oct = octant(&chunk[order[start] as usize]);
                let mut end = start + 1;
                while end < order.len() && end - start < PACKET_WIDTH && octant(&chunk[order[end] as usize]) == oct {
                    end += 1;
                }
                packets.push(order[start..end].iter().map(|&i| (c * CPU_CHUNK) as u32 + i).collect());
                start = end;
            }
        }
        packets
    }

    /// The kernel's packets: slots cut into fours, padding dropped.
    fn gpu_packets(order: &[u32]) -> Vec<Vec<u32>> {
        order.chunks(PACKET_WIDTH).map(|p| p.iter().copied().filter(|&i| i != u32::MAX).collect()).collect()
    }

    /// Rays over every octant, with signed zeros, in a scrambled order, over three CPU chunks.
    fn mixed() -> Vec<Ray> {
        let s = [1.0, -1.0, 0.0, -0.0, 0.5, -2.0];
        (0..(2 * CPU_CHUNK + 67) as u32)
            .map(|i| {
                let k = (i as usize * 7) % 216;
                ray([s[k % 6], s[(k / 6) % 6], s[k / 36]])
            })
            .collect()
    }

    #[test]
    fn packets_are_the_cpu_packets() {
        let rays = mixed();
        let order = packet_order(&rays);
        assert_eq!(order.len() % PACKET_WIDTH, 0);
        assert_eq!(gpu_packets(&order), cpu_packets(&rays));
    }

    #[test]
    fn every_ray_appears_once_and_padding_only_ends_an_octant() {
        let rays = mixed();
        let order = packet_order(&rays);
        let mut seen: Vec<u32> = order.iter().copied().filter(|&i| i != u32::MAX).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..rays.len() as u32).collect::<Vec<_>>());
        for p in order.chunks(PACKET_WIDTH) {
            let real: Vec<u32> = p.iter().copied().take_while(|&i| i != u32::MAX).collect();
            assert!(!real.is_empty(), "a packet of padding only");
            assert!(p[real.len()..].iter().all(|&i| i == u32::MAX), "padding before a ray: {p:?}");
            assert!(real.iter().all(|&i| octant(&rays[i as usize]) == octant(&rays[real[0] as usize])));
        }
    }

    #[test]
    fn packets_never_span_two_chunks() {
        let rays = mixed();
        for p in gpu_packets(&packet_order(&rays)) {
            assert!(p.iter().all(|&i| i as usize / CPU_CHUNK == p[0] as usize / CPU_CHUNK), "{p:?}");
        }
    }

    #[test]
    fn order_is_kept_within_an_octant_and_signed_zero_is_its_own_octant() {
        let rays = [ray([1.0, 1.0, 1.0]), ray([-0.0, 1.0, 1.0]), ray([0.0, 2.0, 1.0]), ray([-1.0, 0.0, 3.0])];
        assert_eq!(packet_order(&rays), [0, 2, u32::MAX, u32::MAX, 1, 3, u32::MAX, u32::MAX]);
    }

    #[test]
    fn a_full_octant_needs_no_padding_and_no_rays_no_slots() {
        let rays = [ray([-1.0, -1.0, -1.0]); 8];
        assert_eq!(packet_order(&rays), (0..8).collect::<Vec<_>>());
        assert!(packet_order(&[]).is_empty());
    }
}
