//! The conformance checks: every method against its reference, ray by ray.

use raytrail_core::method::{Bvh2Method, Method, Query};
use raytrail_core::trace::{Record, Trace, TraceOptions};
use raytrail_core::{Error, Hit, Ray};
use std::fmt;

/// How a method's result for one ray differs from its reference's.
#[derive(Clone, Debug, PartialEq)]
pub enum Difference {
    /// Closest hits differ (primitive id or `t`, bit for bit).
    Hit {
        /// The reference's hit.
        expected: Hit,
        /// The method's hit.
        got: Hit,
    },
    /// Any-hit answers differ.
    Occlusion {
        /// Whether the reference found a hit.
        expected: bool,
        /// Whether the method did.
        got: bool,
    },
    /// A stream method's packet leaf list lacks every leaf holding the ray's reference closest hit.
    IncompleteLeafList {
        /// The leaves (canonical ids) that hold the reference hit's triangle: one, or several
        /// where the tree splits references.
        leaves: Vec<u32>,
        /// The ray's enumeration: its packet, then the packet's leaves.
        got: Vec<u32>,
    },
    /// The batch's report counts the untraceable or the refused rays otherwise than its rays and
    /// hits say (a whole-batch difference, reported at ray 0).
    Count {
        /// What is counted: `untraceable` or `refused`.
        what: &'static str,
        /// The rays that are so.
        expected: usize,
        /// The report's count.
        got: usize,
    },
    /// Node enumerations differ.
    Enumeration {
        /// The reference's visited nodes (canonical ids).
        expected: Vec<u32>,
        /// The method's.
        got: Vec<u32>,
    },
}

/// One ray on which a method parts from its reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Mismatch {
    /// Scene name.
    pub scene: String,
    /// Ray set name.
    pub ray_set: String,
    /// Backend name.
    pub backend: String,
    /// The method checked.
    pub method: Method,
    /// The method it was checked against.
    pub reference: Method,
    /// Closest or any hit.
    pub query: Query,
    /// Index of the ray in its set.
    pub ray_index: usize,
    /// The ray.
    pub ray: Ray,
    /// What differs.
    pub difference: Difference,
}

/// Index of the first entry where two sequences differ (the shorter one's length if one is a
/// prefix of the other), or `None` if they are equal.
pub fn parting_point(a: &[u32], b: &[u32]) -> Option<usize> {
    if a == b {
        return None;
    }
    Some(a.iter().zip(b).position(|(x, y)| x != y).unwrap_or(a.len().min(b.len())))
}

fn write_seq(f: &mut fmt::Formatter<'_>, name: &str, s: &[u32], at: usize) -> fmt::Result {
    // Long enumerations are shown around the parting point.
    let (from, to) = (at.saturating_sub(16), (at + 16).min(s.len()));
    write!(f, "    {name} ({} nodes): ", s.len())?;
    if from > 0 {
        write!(f, "[{from} more] ")?;
    }
    for (i, n) in s[from..to].iter().enumerate() {
        if from + i == at {
            write!(f, ">>{n}<< ")?;
        } else {
            write!(f, "{n} ")?;
        }
    }
    if to < s.len() {
        write!(f, "[{} more]", s.len() - to)?;
    }
    writeln!(f)
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "MISMATCH scene={} rays={} ray#{} backend={} method={} vs {} ({} hit)",
            self.scene,
            self.ray_set,
            self.ray_index,
            self.backend,
            self.method,
            self.reference,
            self.query.name()
        )?;
        let r = &self.ray;
        writeln!(f, "    ray: origin {:?} dir {:?} t in [{:?}, {:?}]", r.origin, r.dir, r.tmin, r.tmax)?;
        match &self.difference {
            Difference::Hit { expected, got } => {
                writeln!(f, "    expected hit {expected:?} (t bits {:#010x})", expected.t.to_bits())?;
                writeln!(f, "    got      hit {got:?} (t bits {:#010x})", got.t.to_bits())
            }
            Difference::Occlusion { expected, got } => writeln!(f, "    expected occluded={expected}, got {got}"),
            Difference::Count { what, expected, got } => {
                writeln!(f, "    the batch has {expected} {what} rays, the report counts {got}")
            }
            Difference::IncompleteLeafList { leaves, got } => {
                writeln!(f, "    the reference hit's triangle is in leaves {leaves:?}, none of which the packet's leaf list has:")?;
                write_seq(f, self.method.name(), got, 0)
            }
            Difference::Enumeration { expected, got } => {
                let at = parting_point(expected, got).unwrap_or(0);
                writeln!(f, "    enumerations part at position {at}:")?;
                write_seq(f, self.reference.name(), expected, at)?;
                write_seq(f, self.method.name(), got, at)
            }
        }
    }
}

/// One ray set's results for one method and query.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The method.
    pub method: Method,
    /// The query.
    pub query: Query,
    /// Hits per ray.
    pub hits: Vec<Hit>,
    /// Enumerations per ray.
    pub enumerations: Vec<Vec<u32>>,
    /// The report's counts of untraceable and of refused rays.
    pub counts: [usize; 2],
}

/// Traces `rays` with every method in `methods` for `query`, recording enumerations.
pub fn trace_all<B: Trace>(
    backend: &B,
    scene: &B::Prepared,
    rays: &[Ray],
    methods: &[Method],
    query: Query,
) -> Result<Vec<Outcome>, Error> {
    trace_all_recording(backend, scene, rays, methods, query, Record::Enumerations)
}

/// [`trace_all`] recording `record` (the outcomes' enumerations are empty unless it is
/// [`Record::Enumerations`]): a check of hits alone need not pay for the node visits, which take
/// about half of a software GPU's time on the suite's scenes.
pub fn trace_all_recording<B: Trace>(
    backend: &B,
    scene: &B::Prepared,
    rays: &[Ray],
    methods: &[Method],
    query: Query,
    record: Record,
) -> Result<Vec<Outcome>, Error> {
    methods
        .iter()
        .map(|&method| {
            let opts = TraceOptions::new(method).query(query).record(record);
            let mut hits = vec![Hit::MISS; rays.len()];
            let report = backend.trace(scene, rays, &opts, &mut hits)?;
            // A backend that recorded none is caught by `compare_backends`, which goes by the
            // reference's enumerations.
            let counts = [report.untraceable, report.refused];
            Ok(Outcome { method, query, hits, enumerations: report.enumerations.unwrap_or_default(), counts })
        })
        .collect()
}

/// Where a check ran.
#[derive(Clone, Copy, Debug)]
pub struct Context<'a> {
    /// Scene name.
    pub scene: &'a str,
    /// Ray set name.
    pub ray_set: &'a str,
    /// Backend name.
    pub backend: &'a str,
}

/// Compares every outcome with its method's reference ([`Method::reference`] for enumerations,
/// the stack method for hits). Returns every mismatch.
pub fn compare(ctx: Context<'_>, rays: &[Ray], outcomes: &[Outcome]) -> Vec<Mismatch> {
    let find = |m: Method, q: Query| outcomes.iter().find(|o| o.method == m && o.query == q);
    let mut out = Vec::new();
    for o in outcomes {
        let mismatch = |i: usize, reference: Method, difference: Difference| Mismatch {
            scene: ctx.scene.to_string(),
            ray_set: ctx.ray_set.to_string(),
            backend: ctx.backend.to_string(),
            method: o.method,
            reference,
            query: o.query,
            ray_index: i,
            ray: rays[i],
            difference,
        };
        if let Some(stack) =
            find(Method::Bvh2(Bvh2Method::Stack), o.query).filter(|_| o.method != Method::Bvh2(Bvh2Method::Stack))
        {
            for (i, (e, g)) in stack.hits.iter().zip(&o.hits).enumerate() {
                if let Some(d) = hit_difference(o.query, e, g) {
                    out.push(mismatch(i, Method::Bvh2(Bvh2Method::Stack), d));
                }
            }
        }
        let reference = o.method.reference();
        if let Some(r) = find(reference, o.query).filter(|_| reference != o.method) {
            for (i, (e, g)) in r.enumerations.iter().zip(&o.enumerations).enumerate() {
                if e != g {
                    out.push(mismatch(i, reference, Difference::Enumeration { expected: e.clone(), got: g.clone() }));
                }
            }
        }
    }
    out
}

/// How a hit `g` differs from the expected `e` for `query`: a closest hit bit for bit, an any
/// hit by whether the ray is occluded at all.
fn hit_difference(query: Query, e: &Hit, g: &Hit) -> Option<Difference> {
    match query {
        Query::Closest => (!e.same_as(g)).then_some(Difference::Hit { expected: *e, got: *g }),
        Query::Any => {
            (e.is_hit() != g.is_hit()).then_some(Difference::Occlusion { expected: e.is_hit(), got: g.is_hit() })
        }
    }
}

/// Compares outcomes with expected ones for the same methods and query, ray by ray: hits bit for
/// bit (any hit: occluded or not) and the counts of untraceable and refused rays. The mismatches
/// name the backend as `versus` ("wgpu vs cpu") and the method as its own reference.
pub fn compare_hits(
    ctx: Context<'_>,
    versus: &str,
    rays: &[Ray],
    expected: &[Outcome],
    got: &[Outcome],
) -> Vec<Mismatch> {
    let mut out = Vec::new();
    for o in got {
        let Some(c) = expected.iter().find(|c| c.method == o.method && c.query == o.query) else {
            continue;
        };
        let mut push = |i: usize, difference: Difference| {
            out.push(Mismatch {
                scene: ctx.scene.to_string(),
                ray_set: ctx.ray_set.to_string(),
                backend: versus.to_string(),
                method: o.method,
                reference: o.method,
                query: o.query,
                ray_index: i,
                ray: rays[i],
                difference,
            })
        };
        for (i, (e, g)) in c.hits.iter().zip(&o.hits).enumerate() {
            if let Some(d) = hit_difference(o.query, e, g) {
                push(i, d);
            }
        }
        // The counts against the rays and hits themselves: every backend counts alike.
        let truth =
            [rays.iter().filter(|r| !r.is_traceable()).count(), o.hits.iter().filter(|h| h.is_refused()).count()];
        for ((what, expected), got) in ["untraceable", "refused"].into_iter().zip(truth).zip(o.counts) {
            if !rays.is_empty() && expected != got {
                push(0, Difference::Count { what, expected, got });
            }
        }
    }
    out
}

/// Compares a backend's outcomes with the CPU's for the same methods and query, ray by ray:
/// hits bit for bit (any hit: occluded or not), the counts ([`compare_hits`]) and enumerations
/// exactly. The mismatches name the backend as `ctx.backend` and the method as its own reference.
pub fn compare_backends(ctx: Context<'_>, rays: &[Ray], cpu: &[Outcome], other: &[Outcome]) -> Vec<Mismatch> {
    let versus = format!("{} vs cpu", ctx.backend);
    let mut out = compare_hits(ctx, &versus, rays, cpu, other);
    for o in other {
        let Some(c) = cpu.iter().find(|c| c.method == o.method && c.query == o.query) else {
            continue;
        };
        // Indexed by the reference's enumerations, so a backend that recorded none (or too few)
        // mismatches instead of being compared over nothing.
        for (i, e) in c.enumerations.iter().enumerate() {
            let g = o.enumerations.get(i).map_or(&[][..], Vec::as_slice);
            if e.as_slice() != g {
                out.push(Mismatch {
                    scene: ctx.scene.to_string(),
                    ray_set: ctx.ray_set.to_string(),
                    backend: versus.clone(),
                    method: o.method,
                    reference: o.method,
                    query: o.query,
                    ray_index: i,
                    ray: rays[i],
                    difference: Difference::Enumeration { expected: e.clone(), got: g.to_vec() },
                });
            }
        }
    }
    out
}

/// Runs every method in `methods` for both queries on `rays`, on `backend` and on `reference`
/// (the CPU): on `backend`, every method against its own reference ([`compare`]), and every
/// outcome against the reference backend's, ray by ray ([`compare_backends`]).
#[allow(clippy::too_many_arguments)]
pub fn check_against<R: Trace, B: Trace>(
    reference: &R,
    reference_scene: &R::Prepared,
    backend: &B,
    scene: &B::Prepared,
    ctx: Context<'_>,
    rays: &[Ray],
    methods: &[Method],
) -> Result<Vec<Mismatch>, Error> {
    let mut all = Vec::new();
    for query in Query::ALL {
        let expected = trace_all(reference, reference_scene, rays, methods, query)?;
        let got = trace_all(backend, scene, rays, methods, query)?;
        all.extend(compare(ctx, rays, &got));
        all.extend(compare_backends(ctx, rays, &expected, &got));
    }
    Ok(all)
}

/// Runs every method for both queries on one ray set and compares; the mismatches found.
pub fn check_ray_set<B: Trace>(
    backend: &B,
    scene: &B::Prepared,
    ctx: Context<'_>,
    rays: &[Ray],
    methods: &[Method],
) -> Result<Vec<Mismatch>, Error> {
    let mut all = Vec::new();
    for query in Query::ALL {
        let outcomes = trace_all(backend, scene, rays, methods, query)?;
        all.extend(compare(ctx, rays, &outcomes));
    }
    Ok(all)
}

/// The completeness of a stream method's leaf lists: every ray whose reference closest hit (the
/// stack method's) lies on a triangle of leaves `leaves.of(prim)` must have one of those leaves in
/// its enumeration (its packet, then the packet's leaves).
pub fn check_complete(
    ctx: Context<'_>,
    rays: &[Ray],
    method: Method,
    reference: &[Hit],
    enumerations: &[Vec<u32>],
    leaves: &PrimLeaves,
) -> Vec<Mismatch> {
    let mut out = Vec::new();
    for (i, hit) in reference.iter().enumerate() {
        if !hit.is_hit() {
            continue;
        }
        let holding = leaves.of(hit.prim);
        let got = enumerations.get(i).map_or(&[][..], Vec::as_slice);
        let listed = got.get(1..).unwrap_or(&[]);
        if !holding.iter().any(|leaf| listed.contains(leaf)) {
            out.push(Mismatch {
                scene: ctx.scene.to_string(),
                ray_set: ctx.ray_set.to_string(),
                backend: ctx.backend.to_string(),
                method,
                reference: Method::Bvh2(Bvh2Method::Stack),
                query: Query::Closest,
                ray_index: i,
                ray: rays[i],
                difference: Difference::IncompleteLeafList { leaves: holding.to_vec(), got: got.to_vec() },
            });
        }
    }
    out
}

/// The leaves (canonical ids) that reference each primitive of a tree: one per primitive, or
/// several where the tree splits references.
#[derive(Clone, Debug)]
pub struct PrimLeaves {
    /// Where each primitive's run of `leaves` starts; one more entry closes the last.
    start: Vec<u32>,
    leaves: Vec<u32>,
}

impl PrimLeaves {
    /// The leaves of every primitive of `bvh`.
    pub fn new(bvh: &raytrail_core::bvh2::Bvh2) -> PrimLeaves {
        let order = bvh.prim_order();
        let mut start = vec![0u32; bvh.prim_count() + 1];
        for &p in order {
            start[p as usize + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut leaves = vec![u32::MAX; order.len()];
        for (id, node) in bvh.nodes().iter().enumerate() {
            if let raytrail_core::bvh2::NodeKind::Leaf { first, count } = node.kind {
                for &p in &order[first as usize..(first + count) as usize] {
                    leaves[fill[p as usize] as usize] = id as u32;
                    fill[p as usize] += 1;
                }
            }
        }
        PrimLeaves { start, leaves }
    }

    /// The leaves that reference primitive `prim` (none for an id the tree does not have).
    pub fn of(&self, prim: u32) -> &[u32] {
        let p = prim as usize;
        match (self.start.get(p), self.start.get(p + 1)) {
            (Some(&a), Some(&b)) => &self.leaves[a as usize..b as usize],
            _ => &[],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_backend_that_recorded_no_enumerations_mismatches() {
        let rays = [Ray::new(glam::Vec3::ZERO, glam::Vec3::X, 0.0, 1.0)];
        let outcome = |enumerations: Vec<Vec<u32>>| Outcome {
            method: Method::Bvh2(Bvh2Method::Hash),
            query: Query::Closest,
            hits: vec![Hit::MISS],
            enumerations,
            counts: [0, 0],
        };
        let ctx = Context { scene: "s", ray_set: "r", backend: "b" };
        let found = compare_backends(ctx, &rays, &[outcome(vec![vec![1, 2]])], &[outcome(Vec::new())]);
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].difference, Difference::Enumeration { expected: vec![1, 2], got: Vec::new() });
    }
    #[test]
    fn a_report_that_miscounts_untraceable_or_refused_rays_mismatches() {
        let good = Ray::new(glam::Vec3::ZERO, glam::Vec3::X, 0.0, 1.0);
        let zero_direction = Ray::new(glam::Vec3::ZERO, glam::Vec3::ZERO, 0.0, 1.0);
        let rays = [good, zero_direction];
        let outcome = |hits: Vec<Hit>, counts: [usize; 2]| Outcome {
            method: Method::Bvh2(Bvh2Method::Stack),
            query: Query::Closest,
            hits,
            enumerations: Vec::new(),
            counts,
        };
        let ctx = Context { scene: "s", ray_set: "r", backend: "b" };
        let cpu = [outcome(vec![Hit::MISS; 2], [1, 0])];
        assert!(compare_backends(ctx, &rays, &cpu, &[outcome(vec![Hit::MISS; 2], [1, 0])]).is_empty());
        let uncounted = compare_backends(ctx, &rays, &cpu, &[outcome(vec![Hit::MISS; 2], [0, 0])]);
        assert_eq!(uncounted[0].difference, Difference::Count { what: "untraceable", expected: 1, got: 0 });
        let refused = [Hit::MISS, Hit::REFUSED];
        let cpu = [outcome(refused.to_vec(), [1, 1])];
        let miscounted = compare_backends(ctx, &rays, &cpu, &[outcome(refused.to_vec(), [1, 0])]);
        assert_eq!(miscounted.len(), 1);
        assert_eq!(miscounted[0].difference, Difference::Count { what: "refused", expected: 1, got: 0 });
        assert!(miscounted[0].to_string().contains("1 refused rays, the report counts 0"));
    }

    #[test]
    fn parting_points() {
        assert_eq!(parting_point(&[1, 2, 3], &[1, 2, 3]), None);
        assert_eq!(parting_point(&[1, 2, 3], &[1, 5, 3]), Some(1));
        assert_eq!(parting_point(&[1, 2], &[1, 2, 3]), Some(2));
    }
}
