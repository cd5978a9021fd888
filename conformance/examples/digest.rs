//! A digest of the whole conformance suite on one backend: every hit, node enumeration and work
//! counter, hashed per case, so that a refactor can show it changed nothing (run before and after,
//! and diff).
//!
//! Walks exactly the suite's cases (scene x builder x ray set x method x query) on one backend
//! and prints, per case, one line:
//!
//! `<scene> <sah|ploc> <ray set> <method> <closest|any> <cpu|wgpu|serial> <rays> <fnv1a-64 hex>`
//!
//! The digest is FNV-1a 64 over the little-endian bytes of: for each ray, hit.t bits (u32),
//! hit.prim (u32), hit.u bits (u32), hit.v bits (u32); then for each ray, its enumeration's
//! length (u32) and canonical ids (u32 each); then every u64 of the report's `Counters` in
//! declaration order (arrays element by element), or the single u64 0xFFFF_FFFF_FFFF_FFFF when
//! the report has no counters.
//!
//! Usage: `cargo run --example digest -p raytrail-conformance -- cpu|wgpu|serial`
//! With `DIGEST_PARTS=<file>`, it also writes per case the digests of each part alone
//! (hits, occluded-or-not, enumerations, counters) to that file, for diagnosing differences.

use raytrail_conformance::paths::{load_mesh_scene, MESH_FILES};
use raytrail_conformance::rays::{ray_sets, RaySetSize};
use raytrail_conformance::scenes::tiny_cases;
use raytrail_conformance::suite::{GENERATED_RAYS, MESH_RAYS, TINY_RAYS};
use raytrail_conformance::{NamedScene, SerialBackend};
use raytrail_core::bvh2::{Bvh2, SahBuilder};
use raytrail_core::method::{Bvh2Method, Method, Query};
use raytrail_core::observe::Counters;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::trace::{Record, Report, Trace, TraceOptions};
use raytrail_core::{Hit, Ray};
use raytrail_cpu::CpuBackend;
use std::io::Write;
use std::sync::Arc;
use std::time::Instant;

/// The names of the u64s hashed from `Counters`, in the order they are hashed.
const COUNTER_FIELDS: &[&str] = &[
    "rays",
    "internal_nodes",
    "leaves",
    "primitive_tests",
    "backtracks",
    "stack_pops",
    "register[0]",
    "register[1]",
    "register[2]",
    "register[3]",
    "hash[0]",
    "hash[1]",
    "iterative",
    "link_reads",
    "restarts",
    "levels[0]",
    "levels[1]",
    "levels[2]",
    "levels[3]",
    "levels[4]",
    "levels[5]",
    "levels[6]",
    "levels[7]",
];

/// Every u64 of `c` in declaration order; the exhaustive destructuring fails to compile if a
/// field is added or renamed.
fn counter_words(c: &Counters) -> Vec<u64> {
    let Counters {
        rays,
        internal_nodes,
        leaves,
        primitive_tests,
        backtracks,
        stack_pops,
        register,
        hash,
        iterative,
        link_reads,
        restarts,
        levels,
    } = *c;
    let mut w = vec![rays, internal_nodes, leaves, primitive_tests, backtracks, stack_pops];
    w.extend(register);
    w.extend(hash);
    w.extend([iterative, link_reads, restarts]);
    w.extend(levels);
    assert_eq!(w.len(), COUNTER_FIELDS.len());
    w
}

/// FNV-1a, 64 bits.
#[derive(Clone, Copy)]
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 ^= u64::from(x);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    fn u32(&mut self, x: u32) {
        self.bytes(&x.to_le_bytes());
    }
    fn u64(&mut self, x: u64) {
        self.bytes(&x.to_le_bytes());
    }
}

fn hash_hits(h: &mut Fnv, hits: &[Hit]) {
    for hit in hits {
        h.u32(hit.t.to_bits());
        h.u32(hit.prim);
        h.u32(hit.u.to_bits());
        h.u32(hit.v.to_bits());
    }
}

fn hash_enumerations(h: &mut Fnv, report: &Report, rays: usize) {
    // Assumes one enumeration per ray (checked), as Record::Enumerations promises.
    let enumerations = report.enumerations.as_ref().expect("enumerations were recorded");
    assert_eq!(enumerations.len(), rays, "one enumeration per ray");
    for e in enumerations {
        h.u32(u32::try_from(e.len()).expect("enumeration length fits u32"));
        for &id in e {
            h.u32(id);
        }
    }
}

fn hash_counters(h: &mut Fnv, report: &Report) {
    match &report.counters {
        Some(c) => counter_words(c).into_iter().for_each(|w| h.u64(w)),
        None => h.u64(u64::MAX),
    }
}

/// The line's digest, and (for DIGEST_PARTS) the digests of each part alone.
struct Digests {
    full: u64,
    hits: u64,
    occluded: u64,
    enumerations: u64,
    counters: u64,
}

fn digest(hits: &[Hit], report: &Report) -> Digests {
    let mut full = Fnv::new();
    hash_hits(&mut full, hits);
    hash_enumerations(&mut full, report, hits.len());
    hash_counters(&mut full, report);
    let mut h = Fnv::new();
    hash_hits(&mut h, hits);
    let mut o = Fnv::new();
    hits.iter().for_each(|x| o.bytes(&[u8::from(x.is_hit())]));
    let mut e = Fnv::new();
    hash_enumerations(&mut e, report, hits.len());
    let mut c = Fnv::new();
    hash_counters(&mut c, report);
    Digests { full: full.0, hits: h.0, occluded: o.0, enumerations: e.0, counters: c.0 }
}

struct Run<B: Trace> {
    backend: B,
    out: std::io::BufWriter<std::io::Stdout>,
    parts: Option<std::io::BufWriter<std::fs::File>>,
    lines: usize,
}

fn options(method: Method, query: Query) -> TraceOptions {
    TraceOptions::new(method).query(query).record(Record::Enumerations)
}

fn trace_on<B: Trace>(backend: &B, scene: &B::Prepared, rays: &[Ray], opts: &TraceOptions) -> (Vec<Hit>, Report) {
    let mut hits = vec![Hit::MISS; rays.len()];
    let report = backend.trace(scene, rays, opts, &mut hits).expect("trace");
    (hits, report)
}

impl<B: Trace> Run<B> {
    /// One scene with one tree: the suite's ray sets (made with the serial backend and the stack
    /// method, as the suite does), every method, both queries, on the chosen backend.
    fn case(&mut self, named: &NamedScene, builder: &str, bvh: Bvh2, size: RaySetSize) {
        let start = Instant::now();
        let prepared = Arc::new(PreparedScene::new(&named.scene, bvh, &Method::ALL).expect("prepare"));
        let serial_scene = SerialBackend.prepare(prepared.clone()).expect("prepare");
        let mut trace_closest = |rays: &[Ray]| {
            let mut hits = vec![Hit::MISS; rays.len()];
            SerialBackend.trace(&serial_scene, rays, &TraceOptions::new(Bvh2Method::Stack), &mut hits).expect("trace");
            hits
        };
        let sets = ray_sets(&named.scene, size, &mut trace_closest);
        let scene = self.backend.prepare(prepared.clone()).expect("prepare on the backend");
        let backend_name = self.backend.name().to_string();
        let mut rays_total = 0;
        for set in &sets {
            rays_total += set.rays.len();
            for method in Method::ALL {
                for query in Query::ALL {
                    let opts = options(method, query);
                    let (hits, report) = trace_on(&self.backend, &scene, &set.rays, &opts);
                    let d = digest(&hits, &report);
                    let key = format!(
                        "{} {} {} {} {} {} {}",
                        named.name,
                        builder,
                        set.kind.name(),
                        method.name(),
                        query.name(),
                        backend_name,
                        set.rays.len()
                    );
                    writeln!(self.out, "{key} {:016x}", d.full).expect("write");
                    if let Some(p) = &mut self.parts {
                        writeln!(
                            p,
                            "{key} hits={:016x} occluded={:016x} enumerations={:016x} counters={:016x}",
                            d.hits, d.occluded, d.enumerations, d.counters
                        )
                        .expect("write");
                    }
                    self.lines += 1;
                }
            }
        }
        self.out.flush().expect("flush");
        if let Some(p) = &mut self.parts {
            p.flush().expect("flush");
        }
        eprintln!(
            "{} ({builder}, {} triangles): {rays_total} rays x {} methods x 2 queries on {backend_name} in {:.1} s",
            named.name,
            named.scene.triangles().len(),
            Method::ALL.len(),
            start.elapsed().as_secs_f64()
        );
    }

    fn sah(&mut self, named: &NamedScene, size: RaySetSize) {
        let bvh = SahBuilder::default().build(named.scene.triangles()).expect("build");
        self.case(named, "sah", bvh, size);
    }

    fn ploc(&mut self, named: &NamedScene, size: RaySetSize) {
        let bvh = raytrail_build::ploc::build_ploc(named.scene.triangles(), 63).expect("build");
        self.case(named, "ploc", bvh, size);
    }
}

use raytrail_conformance::suite::generated_scene;

fn mesh(file: &str) -> NamedScene {
    load_mesh_scene(file).unwrap_or_else(|e| panic!("{e}"))
}

fn main() {
    match std::env::args().nth(1).unwrap_or_default().as_str() {
        "cpu" => walk(CpuBackend::new()),
        "serial" => walk(SerialBackend),
        "wgpu" => {
            let g = raytrail_wgpu::WgpuBackend::new().unwrap_or_else(|e| panic!("wgpu backend unavailable: {e}"));
            eprintln!("wgpu adapter: {}", g.adapter());
            walk(g)
        }
        other => {
            eprintln!("usage: digest cpu|wgpu|serial (got {other:?})");
            std::process::exit(2);
        }
    }
}

/// Every case of the suite, in its order, on `backend`.
fn walk<B: Trace>(backend: B) {
    eprintln!("counter fields (u64 LE, in this order): {}", COUNTER_FIELDS.join(" "));
    let parts = std::env::var_os("DIGEST_PARTS")
        .map(|p| std::io::BufWriter::new(std::fs::File::create(p).expect("create DIGEST_PARTS file")));
    let mut run = Run { backend, out: std::io::BufWriter::new(std::io::stdout()), parts, lines: 0 };
    let start = Instant::now();

    run.sah(&generated_scene("shared_edge_grid"), GENERATED_RAYS);
    let s = generated_scene("sphereflake");
    run.sah(&s, GENERATED_RAYS);
    run.ploc(&s, GENERATED_RAYS);
    let s = generated_scene("triangle_soup");
    run.sah(&s, GENERATED_RAYS);
    run.ploc(&s, GENERATED_RAYS);
    run.sah(&generated_scene("degenerate_stack"), GENERATED_RAYS);
    run.sah(&generated_scene("far_from_origin"), GENERATED_RAYS);
    for s in tiny_cases() {
        run.sah(&s, TINY_RAYS);
    }
    for &file in MESH_FILES {
        run.sah(&mesh(file), MESH_RAYS);
    }
    run.ploc(&mesh("bunny.obj"), MESH_RAYS);

    eprintln!("{} lines in {:.1} s", run.lines, start.elapsed().as_secs_f64());
}
