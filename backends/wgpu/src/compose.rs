//! Shader composition: which WGSL files make a kernel, and the constants shared with the core.
//!
//! A kernel is specialized twice over, so a scene pays only for what it uses:
//! - by composition, for what changes types or pulls in code: the method file, the triangle test,
//!   the key width (`u32`, or a pair of `u32` standing in for `u64`) and the hash tables;
//! - by override constants, for switches the compiler folds away: any hit, recording, the
//!   disjoint-interval mask.

use crate::config::Dispatch;
use crate::stream::shared_parts::{stream_header, INTERSECT_OWN, STREAM_COMMON};
use raytrail_core::intersect::{EDGE_STEP, FAR_PAD, REFINE_SCALE, RELIABLE_LIMIT, SLACK_SCALE, TINY_EDGE};
use raytrail_core::kd::traverse::{PACKET_WIDTH, SHORT_STACK_MAX};
use raytrail_core::key::KeyWidth;
use raytrail_core::method::WideWalk;
use raytrail_core::method::{Bvh2Method, KdMethod, Method, Query, WideMethod};
use raytrail_core::trace::{Record, TriangleTestKind};
use raytrail_core::Error;

/// One WGSL file of `raytrail-shaders`, by name and text.
type Part = (&'static str, &'static str);

macro_rules! part {
    ($source:ident) => {
        (raytrail_shaders::$source.name, raytrail_shaders::$source.text)
    };
}

const PRELUDE: Part = part!(PRELUDE);
const NUMERICS: Part = part!(NUMERICS);
const BOX: Part = part!(BOX);
const WATERTIGHT: Part = part!(TRIANGLE_WATERTIGHT);
const MOLLER_TRUMBORE: Part = part!(TRIANGLE_MOLLER_TRUMBORE);
const QUERY: Part = part!(QUERY);
const RECORD: Part = part!(RECORD);
const BVH_LEAF: Part = part!(BVH_LEAF);
const BVH_STACK: Part = part!(BVH_STACK);
const KEYS32: Part = part!(KEYS32);
const KEYS64: Part = part!(KEYS64);
const HASH: Part = part!(HASH);
const BVH_PARENT_SIBLING: Part = part!(BVH_PARENT_SIBLING);
const BVH_REGISTER: Part = part!(BVH_REGISTER);
const FALLBACK_UNCLE: Part = part!(FALLBACK_UNCLE);
const FALLBACK_HASH: Part = part!(FALLBACK_HASH);
const BVH_RUN: Part = part!(BVH_REGISTER_RUN);
const BVH_RESUME: Part = part!(BVH_RESUME);
const KD_COMMON: Part = part!(KD_COMMON);
const KD_STACK: Part = part!(KD_STACK);
const KD_RESTART: Part = part!(KD_RESTART);
const KD_PACKET: Part = part!(KD_PACKET);
const ENTRY: Part = part!(ENTRY);
const ALL_HITS: Part = part!(ALL_HITS);
const NEAREST: Part = part!(NEAREST);
const DISPATCH_GRID: Part = part!(DISPATCH_GRID);
const DISPATCH_PERSISTENT: Part = part!(DISPATCH_PERSISTENT);
const LOOP_GUARD: Part = part!(LOOP_GUARD);
const WIDE: Part = part!(WIDE);
const WIDE_PACKET: Part = part!(WIDE_PACKET);
const WIDE_RAY_STREAM: Part = part!(WIDE_RAY_STREAM);
const WIDE_STACK: Part = part!(WIDE_STACK);
const WIDE_TRAIL: Part = part!(WIDE_TRAIL);

/// Everything that selects a kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Variant {
    /// The traversal method.
    pub method: Method,
    /// Key and trail width of the tree (BVH2 stackless methods).
    pub keys: KeyWidth,
    /// The triangle test.
    pub triangle: TriangleTestKind,
    /// Closest or any hit.
    pub query: Query,
    /// What is recorded.
    pub record: Record,
    /// How invocations get their rays (grid or persistent threads).
    pub dispatch: DispatchKind,
    /// Invocations per workgroup (the `WORKGROUP_SIZE` override).
    pub workgroup_size: u32,
    /// What the kernel answers: a hit per ray (`query`'s closest or any hit), or a query of the
    /// scene's wide tree beyond it (for the wide stack walk's methods only).
    pub answer: Answer,
}

/// What a kernel answers for each of its work items.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Answer {
    /// One hit per ray, the closest or any one (`query.wgsl`): every method's kernel.
    #[default]
    Hit,
    /// Every hit along each ray, a list per ray (`all_hits.wgsl`).
    AllHits,
    /// The point of the mesh nearest to each query point (`nearest.wgsl`).
    Nearest,
}

/// The dispatch file of a kernel: what [`Dispatch`] compiles to (the number of persistent
/// workgroups is the host's choice, not the kernel's).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum DispatchKind {
    /// `dispatch_grid.wgsl`.
    #[default]
    Grid,
    /// `dispatch_persistent.wgsl`.
    Persistent,
}

impl DispatchKind {
    /// Its files: the loop guard, then the dispatch file.
    fn parts(self) -> [Part; 2] {
        match self {
            DispatchKind::Grid => [LOOP_GUARD, DISPATCH_GRID],
            DispatchKind::Persistent => [LOOP_GUARD, DISPATCH_PERSISTENT],
        }
    }

    /// The dispatch file `method` compiles under `dispatch` ([`Dispatch::for_method`]).
    pub fn of(dispatch: Dispatch, method: Method) -> DispatchKind {
        match dispatch.for_method(method) {
            Dispatch::Persistent { .. } => DispatchKind::Persistent,
            Dispatch::Grid | Dispatch::ByMethod => DispatchKind::Grid,
        }
    }
}

impl Variant {
    /// The variant's name, for labels and messages.
    pub fn label(&self) -> String {
        format!(
            "{}{}/{}/{}/{}/{:?}/{:?}/{}",
            match self.answer {
                Answer::Hit => "",
                Answer::AllHits => "all-hits/",
                Answer::Nearest => "nearest/",
            },
            self.method.name(),
            if self.keys == KeyWidth::W64 { "k64" } else { "k32" },
            match self.triangle {
                TriangleTestKind::Watertight => "watertight",
                TriangleTestKind::MollerTrumbore => "moller-trumbore",
            },
            self.query.name(),
            self.record,
            self.dispatch,
            self.workgroup_size
        )
    }

    /// The WGSL files of this kernel, in order; [`Error::Unsupported`] for a method without one.
    pub fn parts(&self) -> Result<Vec<Part>, Error> {
        if self.answer != Answer::Hit {
            return self.wide_query_parts();
        }
        let mut parts = self.method_parts()?;
        // The stream method's intersection kernel has its own entry point.
        if let Method::Stream(_) = self.method {
            return Ok(parts);
        }
        // The wide packet and stream kernels have their own entry points (a packet or a stream to
        // a workgroup). The packet kernel ends with the loop guard; the stream kernel, whose
        // scratch holds its lists, bounds its steps per round instead (`CPU_ADAPTER_STREAM_STEPS`).
        match self.method.wide().map(|m| m.walk()) {
            Some(WideWalk::Packet) => {
                parts.push(LOOP_GUARD);
                return Ok(parts);
            }
            Some(WideWalk::RayLists) => return Ok(parts),
            _ => {}
        }
        // The kd packet kernel defines its own work items (one packet each).
        if self.method != Method::Kd(KdMethod::Packet) {
            parts.push(ENTRY);
        }
        parts.extend(self.dispatch.parts());
        Ok(parts)
    }

    /// The files of a query of the wide tree beyond a hit per ray: the wide stack walk's, with
    /// `all_hits` in place of `query` (the answer and the work items), or `nearest` after them (a
    /// walk of its own), then the dispatch file; [`Error::Unsupported`] for a method of another
    /// walk.
    fn wide_query_parts(&self) -> Result<Vec<Part>, Error> {
        if !self.method.wide().is_some_and(|m| m.walk() == WideWalk::Stack) {
            let by = "the queries beyond a hit per ray (wide stack walks)";
            return Err(Error::Unsupported { method: self.method.name(), by });
        }
        let mut parts = self.method_parts()?;
        match self.answer {
            Answer::AllHits => {
                for p in &mut parts {
                    if *p == QUERY {
                        *p = ALL_HITS;
                    }
                }
            }
            Answer::Nearest => parts.push(NEAREST),
            Answer::Hit => {}
        }
        parts.extend(self.dispatch.parts());
        Ok(parts)
    }

    /// The files up to and including the method's, without work items or a dispatch file (the
    /// stream method's intersection kernel adds its own entry point to the wide method's files).
    pub(crate) fn method_parts(&self) -> Result<Vec<Part>, Error> {
        let triangle = match self.triangle {
            TriangleTestKind::Watertight => WATERTIGHT,
            TriangleTestKind::MollerTrumbore => MOLLER_TRUMBORE,
        };
        let keys = if self.keys == KeyWidth::W64 { KEYS64 } else { KEYS32 };
        let mut parts = vec![PRELUDE, NUMERICS, BOX, triangle, QUERY, RECORD];
        let method: &[Part] = match self.method {
            Method::Bvh2(Bvh2Method::Stack) | Method::Bvh2(Bvh2Method::StackDisjoint) => &[BVH_LEAF, BVH_STACK],
            Method::Bvh2(Bvh2Method::ParentSibling) => &[BVH_LEAF, keys, BVH_PARENT_SIBLING],
            Method::Bvh2(Bvh2Method::Uncle) => &[BVH_LEAF, keys, FALLBACK_UNCLE, BVH_REGISTER, BVH_RUN],
            Method::Bvh2(Bvh2Method::Hash) | Method::Bvh2(Bvh2Method::HashDisjoint) => {
                &[BVH_LEAF, keys, HASH, FALLBACK_HASH, BVH_REGISTER, BVH_RUN]
            }
            Method::Bvh2(Bvh2Method::HashResume) => &[BVH_LEAF, keys, HASH, FALLBACK_HASH, BVH_REGISTER, BVH_RESUME],
            Method::Kd(KdMethod::Stack) => &[KD_COMMON, KD_STACK],
            Method::Kd(KdMethod::Restart) | Method::Kd(KdMethod::PushDown) | Method::Kd(KdMethod::ShortStack) => {
                &[KD_COMMON, KD_RESTART]
            }
            Method::Kd(KdMethod::Packet) => &[KD_COMMON, KD_PACKET],
            // The single-ray loop too: a packet hands thin subtrees to its rays.
            Method::Wide(m) if m.walk() == WideWalk::Packet => &[WIDE, WIDE_STACK, WIDE_PACKET],
            Method::Wide(m) if m.walk() == WideWalk::RayLists => &[WIDE, WIDE_RAY_STREAM],
            Method::Wide(m) if m.walk() == WideWalk::Trail => &[WIDE, keys, HASH, WIDE_TRAIL],
            Method::Wide(_) => &[WIDE, WIDE_STACK],
            // Its stages are kernels of their own (crate::stream); this is the one that traces:
            // the 8-wide tree's files without work items or dispatch, then the stream's own.
            Method::Stream(_) => {
                let mut parts = Variant { method: Method::Wide(WideMethod::BVH8), ..*self }.method_parts()?;
                parts.push(STREAM_COMMON);
                parts.extend_from_slice(&INTERSECT_OWN);
                return Ok(parts);
            }
            other => return Err(Error::Unsupported { method: other.name(), by: "the wgpu backend" }),
        };
        parts.extend_from_slice(method);
        Ok(parts)
    }

    /// The full WGSL source: the generated constants, then the parts.
    pub fn source(&self) -> Result<String, Error> {
        let mut s = constants_header(self.method);
        if let Method::Stream(_) = self.method {
            s.push_str(&stream_header());
        }
        for (name, text) in self.parts()? {
            s.push_str(&format!("\n// ---- shaders/{name} ----\n"));
            s.push_str(text);
        }
        Ok(s)
    }

    /// Values of the override constants: the method's, and the dispatch's workgroup size.
    pub fn overrides(&self) -> Vec<(&'static str, f64)> {
        let mut o = self.method_overrides();
        if !matches!(self.method, Method::Stream(_)) {
            o.push(("WORKGROUP_SIZE", f64::from(self.workgroup_size)));
        }
        o
    }

    /// Values of the override constants the method's files declare.
    pub(crate) fn method_overrides(&self) -> Vec<(&'static str, f64)> {
        let record = match self.record {
            Record::Nothing => 0.0,
            Record::Counters => 1.0,
            Record::Enumerations => 2.0,
        };
        let disjoint =
            matches!(self.method, Method::Bvh2(Bvh2Method::StackDisjoint) | Method::Bvh2(Bvh2Method::HashDisjoint));
        vec![
            ("ANY_HIT", f64::from(u8::from(self.query == Query::Any))),
            ("RECORD", record),
            ("DISJOINT", f64::from(u8::from(disjoint))),
        ]
    }
}

/// Constants the shaders must share with the core bit for bit, written from the core's own
/// values rather than retyped as WGSL literals (which a compiler would round its own way).
pub(crate) fn constants_header(method: Method) -> String {
    // The stream method's leaves are those of the 8-wide tree.
    let wide_width = match method {
        Method::Stream(_) => 8,
        _ => method.wide().map_or(4, |m| m.width()),
    };
    let kd_mode = match method {
        Method::Kd(KdMethod::Restart) => 0,
        Method::Kd(KdMethod::PushDown) => 1,
        _ => 2,
    };
    format!(
        "// Generated by backends/wgpu/src/compose.rs from raytrail-core's constants.\n\
         const FAR_PAD_BITS: u32 = {:#010x}u;\n\
         const SLACK_SCALE_BITS: u32 = {:#010x}u;\n\
         const RELIABLE_LIMIT_BITS: u32 = {:#010x}u;\n\
         const REFINE_SCALE_BITS: u32 = {:#010x}u;\n\
         const TINY_EDGE_BITS: u32 = {:#010x}u;\n\
         const EDGE_STEP_BITS: u32 = {:#010x}u;\n\
         // kd restart family: 0 restart, 1 push-down, 2 short stack.\n\
         const KD_MODE: u32 = {kd_mode}u;\n\
         const SHORT_STACK_MAX: u32 = {SHORT_STACK_MAX}u;\n\
         const PACKET_WIDTH: u32 = {PACKET_WIDTH}u;\n\
         const WIDE_PACKET: u32 = {wide_packet}u;\n\
         const WIDE_HAND_OVER: u32 = {hand_over}u;\n\
         const WIDE_STREAM: u32 = {wide_stream}u;\n\
         // Children per wide node, and the node keys' bits per level (its log2).\n\
         const WIDE_W: u32 = {wide_width}u;\n\
         const WK_BITS: u32 = {wide_bits}u;\n",
        FAR_PAD.to_bits(),
        SLACK_SCALE.to_bits(),
        RELIABLE_LIMIT.to_bits(),
        REFINE_SCALE.to_bits(),
        TINY_EDGE.to_bits(),
        EDGE_STEP.to_bits(),
        wide_packet = raytrail_core::wide::packet::WIDE_PACKET,
        hand_over = raytrail_core::wide::packet::HAND_OVER,
        wide_stream = raytrail_core::wide::STREAM_RAYS,
        wide_bits = wide_width.trailing_zeros(),
    )
}

// The stream kernel's invocations own 32 rays each, at most 256 of them (wgpu's default limit).
const _: () = assert!(
    raytrail_core::wide::STREAM_RAYS % 32 == 0 && raytrail_core::wide::STREAM_RAYS / 32 <= 256,
    "streams of whole words, one per invocation"
);

// The packet kernel's ray masks are one `u32`.
const _: () = assert!(raytrail_core::wide::packet::WIDE_PACKET <= 32, "wide packets of more than 32 rays");

/// Every variant a scene with keys of width `keys` can ask for, with the default workgroup size
/// and both dispatch files.
pub fn all_variants(keys: KeyWidth) -> impl Iterator<Item = Variant> {
    Method::ALL.into_iter().flat_map(move |method| {
        [TriangleTestKind::Watertight, TriangleTestKind::MollerTrumbore].into_iter().flat_map(move |triangle| {
            [Query::Closest, Query::Any].into_iter().flat_map(move |query| {
                [Record::Nothing, Record::Counters, Record::Enumerations].into_iter().flat_map(move |record| {
                    [DispatchKind::Grid, DispatchKind::Persistent].into_iter().map(move |dispatch| Variant {
                        method,
                        keys,
                        triangle,
                        query,
                        record,
                        dispatch,
                        workgroup_size: crate::GpuConfig::default().workgroup_size,
                        answer: Answer::Hit,
                    })
                })
            })
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// naga as wgpu runs it: parse, then validate with the capabilities the backend requests.
    fn validate(v: &Variant) -> Result<(), String> {
        let src = v.source().expect("every method has a kernel");
        let module = naga::front::wgsl::parse_str(&src).map_err(|e| e.emit_to_string(&src))?;
        let caps = naga::valid::Capabilities::FLOAT64;
        let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps)
            .validate(&module)
            .map_err(|e| e.emit_to_string(&src))?;
        // Every override the host sets exists, and the module validates with them applied.
        let mut constants = naga::back::PipelineConstants::default();
        for (name, value) in v.overrides() {
            constants.insert(name.to_string(), value);
        }
        let stage = Some((naga::ShaderStage::Compute, "main"));
        naga::back::pipeline_constants::process_overrides(&module, &info, stage, &constants)
            .map_err(|e| format!("overrides: {e}"))?;
        Ok(())
    }

    #[test]
    fn every_composition_parses_and_validates_without_an_adapter() {
        let mut failures = Vec::new();
        let mut n = 0;
        for keys in [KeyWidth::W32, KeyWidth::W64] {
            for v in all_variants(keys) {
                n += 1;
                if let Err(e) = validate(&v) {
                    failures.push(format!("{}:\n{e}", v.label()));
                }
            }
        }
        assert!(
            failures.is_empty(),
            "{} of {n} kernels fail naga validation:\n{}",
            failures.len(),
            failures.join("\n")
        );
        assert_eq!(n, 2 * Method::ALL.len() * 2 * 2 * 3 * 2);
    }

    /// The all-hits and nearest-point kernels of every wide stack walk validate under both
    /// dispatch files; every other method is refused by name.
    #[test]
    fn query_kernels_validate_for_the_wide_stack_walks_and_only_for_them() {
        for (answer, file) in [(Answer::AllHits, "shaders/all_hits.wgsl"), (Answer::Nearest, "shaders/nearest.wgsl")] {
            query_kernels_validate(answer, file);
        }
    }

    fn query_kernels_validate(answer: Answer, file: &str) {
        let variant = |method: Method, dispatch| Variant {
            method,
            keys: KeyWidth::W32,
            triangle: TriangleTestKind::Watertight,
            query: Query::Closest,
            record: Record::Nothing,
            dispatch,
            workgroup_size: 64,
            answer,
        };
        let mut walks = 0;
        for method in Method::ALL {
            for dispatch in [DispatchKind::Grid, DispatchKind::Persistent] {
                let v = variant(method, dispatch);
                if method.wide().is_some_and(|m| m.walk() == WideWalk::Stack) {
                    validate(&v).unwrap_or_else(|e| panic!("{}:\n{e}", v.label()));
                    assert!(v.source().unwrap().contains(file));
                    walks += 1;
                } else {
                    assert!(matches!(v.source(), Err(Error::Unsupported { .. })), "{}", v.label());
                }
            }
        }
        assert_eq!(walks, 2 * 4, "bvh4, bvh8, bvh4-naive and bvh8-sah, two dispatch files each");
    }

    /// The kernel cache (pipelines.rs) compiles once per distinct text: methods that differ only
    /// in their tree share a kernel, and methods that walk differently never do.
    #[test]
    fn a_kernel_is_shared_by_the_methods_of_one_walk_only() {
        let text_of = |method: Method| {
            let v = Variant {
                method,
                keys: KeyWidth::W32,
                triangle: TriangleTestKind::Watertight,
                query: Query::Closest,
                record: Record::Nothing,
                dispatch: DispatchKind::Grid,
                workgroup_size: 64,
                answer: Answer::Hit,
            };
            (v.source().expect("a kernel"), v.overrides())
        };
        let text = |m: WideMethod| text_of(Method::Wide(m));
        assert_eq!(text(WideMethod::BVH8), text(WideMethod::BVH8_SAH));
        assert_eq!(text(WideMethod::BVH8_LISTS), text(WideMethod::BVH8_SAH_LISTS));
        assert_ne!(text(WideMethod::BVH8), text(WideMethod::BVH8_PACKET));
        assert_ne!(text(WideMethod::BVH4), text(WideMethod::BVH8));
        let bvh2 = |m: Bvh2Method| text_of(Method::Bvh2(m));
        assert_ne!(bvh2(Bvh2Method::Stack), bvh2(Bvh2Method::StackDisjoint));
    }

    #[test]
    fn constants_are_the_cores_bits() {
        let h = constants_header(Method::Bvh2(Bvh2Method::Stack));
        assert!(h.contains(&format!("{:#010x}", FAR_PAD.to_bits())));
        assert!(h.contains(&format!("{:#010x}", SLACK_SCALE.to_bits())));
        assert!(h.contains(&format!("{:#010x}", REFINE_SCALE.to_bits())));
        assert_eq!(SLACK_SCALE.to_bits(), (1.0f32 / 524288.0).to_bits());
    }
}
