//! A prototype, for measuring only (`AB_PACKET` in `scripts/ab-cpu.sh`): the 8-wide tree traced
//! a packet of `8 G` consecutive rays at a time, eight rays to an AVX register. One node fetch,
//! one child order and one stack per packet; boxes tested per ray with the single-ray test's
//! operations in its order (so a ray's box decisions are its own); leaves tested per ray, or with
//! `AB_PACKET_LEAVES=1` a triangle against eight rays at a time (each lane the block test's
//! operations, with the ray's own axis permutation picked per lane). Closest
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
    packet_leaves: bool,
) {
    assert!(std::arch::is_x86_feature_detected!("avx2"), "the packet prototype needs AVX2");
    // SAFETY: checked just above.
    unsafe {
        match rays_per_packet {
            8 => trace_avx::<1>(mem, root, rays, hits, query, interval, packet_leaves),
            16 => trace_avx::<2>(mem, root, rays, hits, query, interval, packet_leaves),
            32 => trace_avx::<4>(mem, root, rays, hits, query, interval, packet_leaves),
            64 => trace_avx::<8>(mem, root, rays, hits, query, interval, packet_leaves),
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
    packet_leaves: bool,
) {
    let mut stack: Vec<(WideChild, u64)> = Vec::with_capacity(1024);
    for (rs, hs) in rays.chunks(8 * G).zip(hits.chunks_mut(8 * G)) {
        Packet::<G>::new(root, rs, query).trace(mem, root, hs, interval, packet_leaves, &mut stack);
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
        packet_leaves: bool,
        stack: &mut Vec<(WideChild, u64)>,
    ) {
        let mut shear: [Option<ShearGroup>; G] = std::array::from_fn(|_| None);
        // Per lane: the ray's tmin, and its current limit (tmax or the closest hit so far).
        let mut tmin = [[f32::INFINITY; 8]; G];
        let mut lim = [[f32::NEG_INFINITY; 8]; G];
        for (r, s) in self.st.iter().enumerate() {
            if let Some((ctx, q)) = s {
                (tmin[r / 8][r % 8], lim[r / 8][r % 8]) = (ctx.ray.tmin, q.limit());
            }
        }
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
                WideChild::Leaf { first, count } if packet_leaves => {
                    let end = first + count;
                    for g in 0..G {
                        let mut live = ((mask & self.active) >> (8 * g)) as u32 & 0xff;
                        if live == 0 {
                            continue;
                        }
                        let sg = shear[g].get_or_insert_with(|| {
                            ShearGroup::new(&std::array::from_fn(|l| self.st[8 * g + l].as_ref().map(|(c, _)| c.ray)))
                        });
                        let mut pos = first;
                        'tris: while pos < end {
                            let block = mem.wide_block(pos / BLOCK as u32);
                            let tri = block.lane(pos as usize % BLOCK);
                            let h = triangle_vs_rays(sg, &tri, ld(&tmin[g]), ld(&lim[g]));
                            let mut cand = (h.ok | h.slow) & live;
                            while cand != 0 {
                                let l = cand.trailing_zeros() as usize;
                                cand &= cand - 1;
                                let r = 8 * g + l;
                                let (ctx, q) = self.st[r].as_mut().unwrap();
                                let hit = if h.slow & (1 << l) != 0 {
                                    let [a, b, c] = &tri;
                                    Watertight::intersect_in_place(&ctx.tri(), [a, b, c], ctx.ray.tmin, q.limit())
                                } else {
                                    Some(TriangleHit { t: h.t[l], u: h.u[l], v: h.v[l] })
                                };
                                if let Some(hit) = hit {
                                    if q.offer(hit, mem.prim(pos)) {
                                        if any {
                                            live &= !(1 << l);
                                            self.active &= !(1 << r);
                                        } else {
                                            lim[g][l] = q.limit();
                                            self.thi[g][l] = ctx.box_interval(q.limit()).1;
                                        }
                                    }
                                }
                            }
                            if live == 0 {
                                break 'tris;
                            }
                            pos += 1;
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

/// The watertight test's per-ray constants (`Watertight::prepare`'s, recomputed here with the same
/// operations, since its fields are private) as lane masks and values of one register group.
struct ShearGroup {
    /// Per ray axis (x, y, z of ray space): lanes whose source axis is 0, and 1 (else 2).
    pick: [[__m256; 2]; 3],
    o: [__m256; 3],
    s: [__m256; 3],
}

impl ShearGroup {
    fn new(rays: &[Option<Ray>; 8]) -> Self {
        let (mut k, mut o, mut s) = ([[2usize; 3]; 8], [[0f32; 8]; 3], [[1f32; 8]; 3]);
        for (l, r) in rays.iter().enumerate() {
            let Some(r) = r else { continue };
            let (d, org) = (r.dir, r.origin);
            let a = d.map(f32::abs);
            let x_dom = a[0] >= a[1] && a[0] >= a[2];
            let y_dom = !x_dom && a[1] >= a[2];
            let kz = if x_dom {
                0
            } else if y_dom {
                1
            } else {
                2
            };
            let (mut kx, mut ky) = ([1, 2, 0][kz], [2, 0, 1][kz]);
            if d[kz] < 0.0 {
                (kx, ky) = (ky, kx);
            }
            k[l] = [kx, ky, kz];
            for (i, &ax) in [kx, ky, kz].iter().enumerate() {
                o[i][l] = org[ax];
            }
            (s[0][l], s[1][l], s[2][l]) = (d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
        }
        // SAFETY: only called from the AVX2 path.
        unsafe {
            let mask = |i: usize, axis: usize| {
                let m: [f32; 8] = std::array::from_fn(|l| if k[l][i] == axis { f32::from_bits(!0) } else { 0.0 });
                _mm256_loadu_ps(m.as_ptr())
            };
            let ld = |v: &[f32; 8]| _mm256_loadu_ps(v.as_ptr());
            ShearGroup {
                pick: [[mask(0, 0), mask(0, 1)], [mask(1, 0), mask(1, 1)], [mask(2, 0), mask(2, 1)]],
                o: [ld(&o[0]), ld(&o[1]), ld(&o[2])],
                s: [ld(&s[0]), ld(&s[1]), ld(&s[2])],
            }
        }
    }
}

/// What one triangle against a group's eight rays gives per lane: hit lanes, lanes the scalar
/// test must decide (a zero edge function, or flagged for the f64 refinement), and `t, u, v`.
struct LaneHits {
    ok: u32,
    slow: u32,
    t: [f32; 8],
    u: [f32; 8],
    v: [f32; 8],
}

/// Triangle `tri` against the eight rays of `g`, each lane the operations of the block test's lane
/// (`Watertight::intersect_block`) in its order, so each answer is the scalar test's bit for bit.
#[inline(always)]
unsafe fn triangle_vs_rays(g: &ShearGroup, tri: &[[f32; 3]; 3], tmin: __m256, tmax: __m256) -> LaneHits {
    let s = _mm256_set1_ps;
    let rel = |p: &[f32; 3]| {
        let pick = |i: usize| {
            let [m0, m1] = g.pick[i];
            _mm256_blendv_ps(_mm256_blendv_ps(s(p[2]), s(p[1]), m1), s(p[0]), m0)
        };
        (_mm256_sub_ps(pick(0), g.o[0]), _mm256_sub_ps(pick(1), g.o[1]), _mm256_sub_ps(pick(2), g.o[2]))
    };
    let ((a0, a1, a2), (b0, b1, b2), (c0, c1, c2)) = (rel(&tri[0]), rel(&tri[1]), rel(&tri[2]));
    let [sx, sy, sz] = g.s;
    let ax = _mm256_sub_ps(a0, _mm256_mul_ps(sx, a2));
    let ay = _mm256_sub_ps(a1, _mm256_mul_ps(sy, a2));
    let bx = _mm256_sub_ps(b0, _mm256_mul_ps(sx, b2));
    let by = _mm256_sub_ps(b1, _mm256_mul_ps(sy, b2));
    let cx = _mm256_sub_ps(c0, _mm256_mul_ps(sx, c2));
    let cy = _mm256_sub_ps(c1, _mm256_mul_ps(sy, c2));
    let u = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
    let v = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
    let w = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
    let z = s(0.0);
    let cmp_eq = |x| _mm256_cmp_ps::<_CMP_EQ_OQ>(x, z);
    let (lt, gt) = (|x| _mm256_cmp_ps::<_CMP_LT_OQ>(x, z), |x| _mm256_cmp_ps::<_CMP_GT_OQ>(x, z));
    let zero = _mm256_or_ps(_mm256_or_ps(cmp_eq(u), cmp_eq(v)), cmp_eq(w));
    let neg = _mm256_or_ps(_mm256_or_ps(lt(u), lt(v)), lt(w));
    let pos = _mm256_or_ps(_mm256_or_ps(gt(u), gt(v)), gt(w));
    let det = _mm256_add_ps(_mm256_add_ps(u, v), w);
    let (az, bz, cz) = (_mm256_mul_ps(sz, a2), _mm256_mul_ps(sz, b2), _mm256_mul_ps(sz, c2));
    let num = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(u, az), _mm256_mul_ps(v, bz)), _mm256_mul_ps(w, cz));
    let t = _mm256_div_ps(num, det);
    let abs = |x: __m256| _mm256_andnot_ps(s(-0.0), x);
    let finite = _mm256_cmp_ps::<_CMP_LT_OQ>(abs(t), s(f32::INFINITY));
    let det_ok = _mm256_cmp_ps::<_CMP_NEQ_UQ>(det, z);
    let ahead = _mm256_and_ps(
        _mm256_andnot_ps(_mm256_and_ps(neg, pos), det_ok),
        _mm256_and_ps(finite, _mm256_cmp_ps::<_CMP_NLT_UQ>(t, tmin)),
    );
    let ok = _mm256_and_ps(ahead, _mm256_cmp_ps::<_CMP_NGT_UQ>(t, tmax));
    let zero = _mm256_movemask_ps(zero) as u32;
    let mut slow = zero;
    let screened = _mm256_movemask_ps(ahead) as u32 & !zero;
    if screened != 0 {
        let m = |p0, p1, p2| _mm256_add_ps(_mm256_add_ps(abs(p0), abs(p1)), _mm256_add_ps(abs(p2), abs(p2)));
        let (ma, mb, mc) = (m(a0, a1, a2), m(b0, b1, b2), m(c0, c1, c2));
        let (sa, sb, sc) =
            (_mm256_add_ps(abs(ax), abs(ay)), _mm256_add_ps(abs(bx), abs(by)), _mm256_add_ps(abs(cx), abs(cy)));
        let e = |mp, sq, mq, sp| {
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(mp, sq), _mm256_mul_ps(mq, sp)), _mm256_mul_ps(sp, sq))
        };
        let (eu, ev, ew) = (e(mb, sc, mc, sb), e(mc, sa, ma, sc), e(ma, sb, mb, sa));
        let dz = |zz| abs(_mm256_sub_ps(zz, t));
        let lhs = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(eu, dz(az)), _mm256_mul_ps(ev, dz(bz))),
            _mm256_mul_ps(ew, dz(cz)),
        );
        let rhs = _mm256_mul_ps(s(rc::intersect::REFINE_SCALE), abs(_mm256_mul_ps(t, det)));
        slow |= _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(lhs, rhs)) as u32 & screened;
    }
    let store = |x: __m256| {
        let mut out = [0f32; 8];
        _mm256_storeu_ps(out.as_mut_ptr(), x);
        out
    };
    LaneHits {
        ok: _mm256_movemask_ps(ok) as u32,
        slow,
        t: store(t),
        u: store(_mm256_div_ps(v, det)),
        v: store(_mm256_div_ps(w, det)),
    }
}
