//! A prototype, for measuring only (`AB_PACKET` in `scripts/ab-cpu.sh`): the 8-wide tree traced
//! a packet of `8 G` consecutive rays at a time, eight rays to an AVX register. One node fetch,
//! one child order and one stack per packet; boxes tested per ray with the single-ray test's
//! operations in its order (so a ray's box decisions are its own); leaves tested per ray. Closest
//! hits do not depend on the order of visits (ties go to the smaller primitive id), so the answers
//! equal the single-ray method's, which the harness checks; the enumeration is the packet's, so
//! this is no method of the library.
//!
//! `AB_PACKET=ia` first culls the node's children for the whole packet with an interval test
//! (lanes = children) over the packet's ranges of origins and reciprocal directions. Rounding is
//! monotonic, so the interval ends bound every ray's computed distances and the cull never drops
//! a child that a ray's own test would keep. Packets whose directions differ in sign on an axis,
//! or have a zero component, skip it. `AB_PACKET_RAYS` (8, 16, 32 or 64) sets the packet size.
//!
//! Children are ordered by the nearest entry over the packet's rays (slot order for any hit).

use rc::intersect::{NoPair, TriangleHit, TriangleTest, Watertight, BLOCK, FAR_PAD};
use rc::method::Query;
use rc::traverse::{begin, QueryState};
use rc::wide::traverse::{WideRayContext, WideRoot};
use rc::wide::{WideChild, WideMemory, WideNode, WideSliceMemory, EMPTY_CHILD};
use rc::{Hit, Ray};
use std::arch::x86_64::*;

/// Traces `rays` in packets of `rays_per_packet` consecutive rays; `interval` turns the cull on.
pub fn trace(
    mem: &WideSliceMemory<'_, 8>,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    interval: bool,
    rays_per_packet: usize,
) {
    assert!(std::arch::is_x86_feature_detected!("avx2"), "the packet prototype needs AVX2");
    // SAFETY: checked just above.
    unsafe {
        match rays_per_packet {
            8 => trace_avx::<1>(mem, root, rays, hits, query, interval),
            16 => trace_avx::<2>(mem, root, rays, hits, query, interval),
            32 => trace_avx::<4>(mem, root, rays, hits, query, interval),
            64 => trace_avx::<8>(mem, root, rays, hits, query, interval),
            n => panic!("AB_PACKET_RAYS: 8, 16, 32 or 64, not {n}"),
        }
    }
}

#[target_feature(enable = "avx2")]
unsafe fn trace_avx<const G: usize>(
    mem: &WideSliceMemory<'_, 8>,
    root: WideRoot,
    rays: &[Ray],
    hits: &mut [Hit],
    query: Query,
    interval: bool,
) {
    let mut stack: Vec<(WideChild, u64)> = Vec::with_capacity(1024);
    for (rs, hs) in rays.chunks(8 * G).zip(hits.chunks_mut(8 * G)) {
        Packet::<G>::new(root, rs, query).trace(mem, root, hs, interval, &mut stack);
    }
}

/// The smallest and largest of the lanes in `mask`.
fn range(v: &[f32; 8], mask: u64) -> (f32, f32) {
    (0..8)
        .filter(|i| mask & (1 << i) != 0)
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), i| (l.min(v[i]), h.max(v[i])))
}

/// A packet's rays, eight to a register group.
struct Packet<const G: usize> {
    st: Vec<Option<(WideRayContext<Watertight>, QueryState)>>,
    o: [[[f32; 8]; G]; 3],
    inv: [[[f32; 8]; G]; 3],
    tlo: [[f32; 8]; G],
    thi: [[f32; 8]; G],
    slack: [[f32; 8]; G],
    active: u64,
    any: bool,
}

impl<const G: usize> Packet<G> {
    fn new(root: WideRoot, rays: &[Ray], query: Query) -> Self {
        let mut p = Packet {
            st: (0..8 * G)
                .map(|i| rays.get(i).and_then(|r| begin::<Watertight, NoPair>(r, root.scene_scale, query)))
                .collect(),
            o: [[[0.0; 8]; G]; 3],
            inv: [[[0.0; 8]; G]; 3],
            tlo: [[f32::INFINITY; 8]; G],
            thi: [[f32::NEG_INFINITY; 8]; G],
            slack: [[0.0; 8]; G],
            active: 0,
            any: query == Query::Any,
        };
        for i in 0..8 * G {
            if let Some((ctx, q)) = &p.st[i] {
                let (g, l) = (i / 8, i % 8);
                for a in 0..3 {
                    p.o[a][g][l] = ctx.slab.origin[a];
                    p.inv[a][g][l] = ctx.slab.inv_dir[a];
                }
                let (lo, hi) = ctx.box_interval(q.limit());
                (p.tlo[g][l], p.thi[g][l], p.slack[g][l]) = (lo, hi, ctx.slab.slack);
                p.active |= 1 << i;
            }
        }
        p
    }

    /// The smallest and largest value of `v` over the active rays.
    fn range_of(&self, v: &[[f32; 8]; G]) -> (f32, f32) {
        let mut out = (f32::INFINITY, f32::NEG_INFINITY);
        for (g, lanes) in v.iter().enumerate() {
            let (l, h) = range(lanes, self.active >> (8 * g));
            out = (out.0.min(l), out.1.max(h));
        }
        out
    }

    #[inline(always)]
    unsafe fn trace(
        mut self,
        mem: &WideSliceMemory<'_, 8>,
        root: WideRoot,
        hits: &mut [Hit],
        interval: bool,
        stack: &mut Vec<(WideChild, u64)>,
    ) {
        let any = self.any;
        let orng = [0, 1, 2].map(|a| self.range_of(&self.o[a]));
        let irng = [0, 1, 2].map(|a| self.range_of(&self.inv[a]));
        let one_sign = irng.iter().all(|&(l, h)| (l > 0.0 && h.is_finite()) || (h < 0.0 && l.is_finite()));
        let cull = interval && one_sign;
        let (tlo_min, slack_max) = (self.range_of(&self.tlo).0, self.range_of(&self.slack).1);
        let mut thi_max = self.range_of(&self.thi).1;
        let ld = |a: &[f32; 8]| _mm256_loadu_ps(a.as_ptr());
        let pad = _mm256_set1_ps(FAR_PAD);
        stack.clear();
        let mut cur = Some((root.root, self.active));
        while let Some((child, mask)) = cur.take() {
            match child {
                WideChild::Node(idx) => {
                    let node = &mem.nodes[idx as usize];
                    let survivors =
                        if cull { cull_children(node, &orng, &irng, tlo_min, thi_max, slack_max, pad) } else { 0xff };
                    // (key, slot, rays) of the hit children.
                    let mut list = [(0f32, 0u32, 0u64); 8];
                    let mut n = 0;
                    let mut sv = survivors;
                    while sv != 0 {
                        let c = sv.trailing_zeros() as usize;
                        sv &= sv - 1;
                        if node.child[c] == EMPTY_CHILD {
                            break;
                        }
                        let mut m = 0u64;
                        let mut key = _mm256_set1_ps(f32::INFINITY);
                        for g in 0..G {
                            if (mask >> (8 * g)) & 0xff == 0 {
                                continue;
                            }
                            let (mut te, mut tx) = (ld(&self.tlo[g]), ld(&self.thi[g]));
                            for a in 0..3 {
                                let (l, h) = (_mm256_set1_ps(node.lo[a][c]), _mm256_set1_ps(node.hi[a][c]));
                                let (o, inv) = (ld(&self.o[a][g]), ld(&self.inv[a][g]));
                                let (near, far) = (_mm256_blendv_ps(l, h, inv), _mm256_blendv_ps(h, l, inv));
                                let tn = _mm256_mul_ps(_mm256_sub_ps(near, o), inv);
                                let tf = _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(far, o), inv), pad);
                                te = _mm256_max_ps(tn, te);
                                tx = _mm256_min_ps(tf, tx);
                            }
                            let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(te, _mm256_add_ps(tx, ld(&self.slack[g])));
                            let gm = (_mm256_movemask_ps(hit) as u64) << (8 * g) & mask;
                            if gm != 0 && !any {
                                key = _mm256_min_ps(_mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), te, hit), key);
                            }
                            m |= gm;
                        }
                        if m != 0 {
                            let h = _mm_min_ps(_mm256_castps256_ps128(key), _mm256_extractf128_ps::<1>(key));
                            let h = _mm_min_ps(h, _mm_movehl_ps(h, h));
                            list[n] = (_mm_cvtss_f32(_mm_min_ss(h, _mm_shuffle_ps::<1>(h, h))), c as u32, m);
                            n += 1;
                        }
                    }
                    if n == 0 {
                        cur = pop(stack, self.active);
                        continue;
                    }
                    if !any {
                        for i in 1..n {
                            let mut j = i;
                            while j > 0 && list[j].0 < list[j - 1].0 {
                                list.swap(j, j - 1);
                                j -= 1;
                            }
                        }
                    }
                    for &(_, c, m) in list[1..n].iter().rev() {
                        stack.push((node.child_ref(c as usize).unwrap(), m));
                    }
                    cur = Some((node.child_ref(list[0].1 as usize).unwrap(), list[0].2));
                }
                WideChild::Leaf { first, count } => {
                    let mut m = mask & self.active;
                    while m != 0 {
                        let r = m.trailing_zeros() as usize;
                        m &= m - 1;
                        let (ctx, q) = self.st[r].as_mut().unwrap();
                        let per_ray = ctx.tri();
                        let (end, mut pos) = (first + count, first);
                        'blocks: while pos < end {
                            let block = mem.wide_block(pos / BLOCK as u32);
                            let hits = Watertight::intersect_block(&per_ray, &block, ctx.ray.tmin, q.limit());
                            let n = (end - pos).min(BLOCK as u32);
                            let mut live = hits.mask & ((1 << n) - 1);
                            while live != 0 {
                                let lane = live.trailing_zeros() as usize;
                                live &= live - 1;
                                let h = TriangleHit { t: hits.t[lane], u: hits.u[lane], v: hits.v[lane] };
                                if q.offer(h, mem.prim(pos + lane as u32)) && any {
                                    self.active &= !(1 << r);
                                    break 'blocks;
                                }
                            }
                            pos += n;
                        }
                        if !any {
                            self.thi[r / 8][r % 8] = ctx.box_interval(q.limit()).1;
                        }
                    }
                    if self.active == 0 {
                        break;
                    }
                    if !any {
                        thi_max = self.range_of(&self.thi).1;
                    }
                    cur = pop(stack, self.active);
                }
            }
        }
        for (h, s) in hits.iter_mut().zip(&self.st) {
            *h = s.as_ref().map_or(Hit::MISS, |(_, q)| q.hit);
        }
    }
}

/// The children no ray of the packet can hit, culled by the interval test; returns the others.
#[inline(always)]
unsafe fn cull_children(
    node: &WideNode<8>,
    orng: &[(f32, f32); 3],
    irng: &[(f32, f32); 3],
    tlo_min: f32,
    thi_max: f32,
    slack_max: f32,
    pad: __m256,
) -> u32 {
    let (mut te, mut tx) = (_mm256_set1_ps(tlo_min), _mm256_set1_ps(thi_max));
    for a in 0..3 {
        let (l, h) = (_mm256_loadu_ps(node.lo[a].as_ptr()), _mm256_loadu_ps(node.hi[a].as_ptr()));
        let (near, far) = if irng[a].0 < 0.0 { (h, l) } else { (l, h) };
        let s = _mm256_set1_ps;
        let (o0, o1, i0, i1) = (s(orng[a].0), s(orng[a].1), s(irng[a].0), s(irng[a].1));
        let corners = |p: __m256, q: __m256| {
            [_mm256_mul_ps(p, i0), _mm256_mul_ps(p, i1), _mm256_mul_ps(q, i0), _mm256_mul_ps(q, i1)]
        };
        let n = corners(_mm256_sub_ps(near, o1), _mm256_sub_ps(near, o0));
        let f = corners(_mm256_sub_ps(far, o1), _mm256_sub_ps(far, o0));
        let tn = _mm256_min_ps(_mm256_min_ps(n[0], n[1]), _mm256_min_ps(n[2], n[3]));
        let tf = _mm256_max_ps(_mm256_max_ps(f[0], f[1]), _mm256_max_ps(f[2], f[3]));
        te = _mm256_max_ps(te, tn);
        tx = _mm256_min_ps(tx, _mm256_max_ps(_mm256_mul_ps(tf, pad), tf));
    }
    let out = _mm256_cmp_ps::<_CMP_GT_OQ>(te, _mm256_add_ps(tx, _mm256_set1_ps(slack_max)));
    !(_mm256_movemask_ps(out) as u32) & 0xff
}

/// The next postponed child with a ray still looking, with those rays.
#[inline(always)]
fn pop(stack: &mut Vec<(WideChild, u64)>, active: u64) -> Option<(WideChild, u64)> {
    while let Some((c, m)) = stack.pop() {
        if m & active != 0 {
            return Some((c, m & active));
        }
    }
    None
}
