//! raytrail's WGSL kernels as source text, one file per concern (README.md here says which files
//! make which method's kernel). `raytrail-wgpu` composes them per method, key width, triangle test,
//! query and recording; a tool that wants the plain sources (a linter, another WGSL host) reads
//! them here.
#![no_std]
#![warn(missing_docs)]

/// One WGSL file: its name in this folder and its text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Source {
    /// File name, for example `box.wgsl`.
    pub name: &'static str,
    /// The file's text.
    pub text: &'static str,
}

/// `all_hits.wgsl`.
pub const ALL_HITS: Source = Source { name: "all_hits.wgsl", text: include_str!("all_hits.wgsl") };

/// `box.wgsl`.
pub const BOX: Source = Source { name: "box.wgsl", text: include_str!("box.wgsl") };

/// `bvh_leaf.wgsl`.
pub const BVH_LEAF: Source = Source { name: "bvh_leaf.wgsl", text: include_str!("bvh_leaf.wgsl") };

/// `bvh_parent_sibling.wgsl`.
pub const BVH_PARENT_SIBLING: Source =
    Source { name: "bvh_parent_sibling.wgsl", text: include_str!("bvh_parent_sibling.wgsl") };

/// `bvh_register.wgsl`.
pub const BVH_REGISTER: Source = Source { name: "bvh_register.wgsl", text: include_str!("bvh_register.wgsl") };

/// `bvh_register_run.wgsl`.
pub const BVH_REGISTER_RUN: Source =
    Source { name: "bvh_register_run.wgsl", text: include_str!("bvh_register_run.wgsl") };

/// `bvh_resume.wgsl`.
pub const BVH_RESUME: Source = Source { name: "bvh_resume.wgsl", text: include_str!("bvh_resume.wgsl") };

/// `bvh_stack.wgsl`.
pub const BVH_STACK: Source = Source { name: "bvh_stack.wgsl", text: include_str!("bvh_stack.wgsl") };

/// `dispatch_grid.wgsl`.
pub const DISPATCH_GRID: Source = Source { name: "dispatch_grid.wgsl", text: include_str!("dispatch_grid.wgsl") };

/// `dispatch_persistent.wgsl`.
pub const DISPATCH_PERSISTENT: Source =
    Source { name: "dispatch_persistent.wgsl", text: include_str!("dispatch_persistent.wgsl") };

/// `entry.wgsl`.
pub const ENTRY: Source = Source { name: "entry.wgsl", text: include_str!("entry.wgsl") };

/// `fallback_hash.wgsl`.
pub const FALLBACK_HASH: Source = Source { name: "fallback_hash.wgsl", text: include_str!("fallback_hash.wgsl") };

/// `fallback_uncle.wgsl`.
pub const FALLBACK_UNCLE: Source = Source { name: "fallback_uncle.wgsl", text: include_str!("fallback_uncle.wgsl") };

/// `hash.wgsl`.
pub const HASH: Source = Source { name: "hash.wgsl", text: include_str!("hash.wgsl") };

/// `kd_common.wgsl`.
pub const KD_COMMON: Source = Source { name: "kd_common.wgsl", text: include_str!("kd_common.wgsl") };

/// `kd_packet.wgsl`.
pub const KD_PACKET: Source = Source { name: "kd_packet.wgsl", text: include_str!("kd_packet.wgsl") };

/// `kd_restart.wgsl`.
pub const KD_RESTART: Source = Source { name: "kd_restart.wgsl", text: include_str!("kd_restart.wgsl") };

/// `kd_stack.wgsl`.
pub const KD_STACK: Source = Source { name: "kd_stack.wgsl", text: include_str!("kd_stack.wgsl") };

/// `keys32.wgsl`.
pub const KEYS32: Source = Source { name: "keys32.wgsl", text: include_str!("keys32.wgsl") };

/// `keys64.wgsl`.
pub const KEYS64: Source = Source { name: "keys64.wgsl", text: include_str!("keys64.wgsl") };

/// `loop_guard.wgsl`.
pub const LOOP_GUARD: Source = Source { name: "loop_guard.wgsl", text: include_str!("loop_guard.wgsl") };

/// `nearest.wgsl`.
pub const NEAREST: Source = Source { name: "nearest.wgsl", text: include_str!("nearest.wgsl") };

/// `numerics.wgsl`.
pub const NUMERICS: Source = Source { name: "numerics.wgsl", text: include_str!("numerics.wgsl") };

/// `prelude.wgsl`.
pub const PRELUDE: Source = Source { name: "prelude.wgsl", text: include_str!("prelude.wgsl") };

/// `probe.wgsl`.
pub const PROBE: Source = Source { name: "probe.wgsl", text: include_str!("probe.wgsl") };

/// `query.wgsl`.
pub const QUERY: Source = Source { name: "query.wgsl", text: include_str!("query.wgsl") };

/// `record.wgsl`.
pub const RECORD: Source = Source { name: "record.wgsl", text: include_str!("record.wgsl") };

/// `stream_common.wgsl`.
pub const STREAM_COMMON: Source = Source { name: "stream_common.wgsl", text: include_str!("stream_common.wgsl") };

/// `stream_compact.wgsl`.
pub const STREAM_COMPACT: Source = Source { name: "stream_compact.wgsl", text: include_str!("stream_compact.wgsl") };

/// `stream_cull.wgsl`.
pub const STREAM_CULL: Source = Source { name: "stream_cull.wgsl", text: include_str!("stream_cull.wgsl") };

/// `stream_expand.wgsl`.
pub const STREAM_EXPAND: Source = Source { name: "stream_expand.wgsl", text: include_str!("stream_expand.wgsl") };

/// `stream_fill.wgsl`.
pub const STREAM_FILL: Source = Source { name: "stream_fill.wgsl", text: include_str!("stream_fill.wgsl") };

/// `stream_frustum.wgsl`.
pub const STREAM_FRUSTUM: Source = Source { name: "stream_frustum.wgsl", text: include_str!("stream_frustum.wgsl") };

/// `stream_gather.wgsl`.
pub const STREAM_GATHER: Source = Source { name: "stream_gather.wgsl", text: include_str!("stream_gather.wgsl") };

/// `stream_heads.wgsl`.
pub const STREAM_HEADS: Source = Source { name: "stream_heads.wgsl", text: include_str!("stream_heads.wgsl") };

/// `stream_intersect.wgsl`.
pub const STREAM_INTERSECT: Source =
    Source { name: "stream_intersect.wgsl", text: include_str!("stream_intersect.wgsl") };

/// `stream_keys.wgsl`.
pub const STREAM_KEYS: Source = Source { name: "stream_keys.wgsl", text: include_str!("stream_keys.wgsl") };

/// `stream_levels.wgsl`.
pub const STREAM_LEVELS: Source = Source { name: "stream_levels.wgsl", text: include_str!("stream_levels.wgsl") };

/// `stream_packet_counts.wgsl`.
pub const STREAM_PACKET_COUNTS: Source =
    Source { name: "stream_packet_counts.wgsl", text: include_str!("stream_packet_counts.wgsl") };

/// `stream_pair_scatter.wgsl`.
pub const STREAM_PAIR_SCATTER: Source =
    Source { name: "stream_pair_scatter.wgsl", text: include_str!("stream_pair_scatter.wgsl") };

/// `stream_radix_count.wgsl`.
pub const STREAM_RADIX_COUNT: Source =
    Source { name: "stream_radix_count.wgsl", text: include_str!("stream_radix_count.wgsl") };

/// `stream_radix_scatter.wgsl`.
pub const STREAM_RADIX_SCATTER: Source =
    Source { name: "stream_radix_scatter.wgsl", text: include_str!("stream_radix_scatter.wgsl") };

/// `stream_ranges.wgsl`.
pub const STREAM_RANGES: Source = Source { name: "stream_ranges.wgsl", text: include_str!("stream_ranges.wgsl") };

/// `stream_roots_flag.wgsl`.
pub const STREAM_ROOTS_FLAG: Source =
    Source { name: "stream_roots_flag.wgsl", text: include_str!("stream_roots_flag.wgsl") };

/// `stream_roots_scatter.wgsl`.
pub const STREAM_ROOTS_SCATTER: Source =
    Source { name: "stream_roots_scatter.wgsl", text: include_str!("stream_roots_scatter.wgsl") };

/// `stream_scan.wgsl`.
pub const STREAM_SCAN: Source = Source { name: "stream_scan.wgsl", text: include_str!("stream_scan.wgsl") };

/// `stream_scan_add.wgsl`.
pub const STREAM_SCAN_ADD: Source = Source { name: "stream_scan_add.wgsl", text: include_str!("stream_scan_add.wgsl") };

/// `stream_segscan.wgsl`.
pub const STREAM_SEGSCAN: Source = Source { name: "stream_segscan.wgsl", text: include_str!("stream_segscan.wgsl") };

/// `stream_segscan_add.wgsl`.
pub const STREAM_SEGSCAN_ADD: Source =
    Source { name: "stream_segscan_add.wgsl", text: include_str!("stream_segscan_add.wgsl") };

/// `stream_sizes.wgsl`.
pub const STREAM_SIZES: Source = Source { name: "stream_sizes.wgsl", text: include_str!("stream_sizes.wgsl") };

/// `stream_skeleton.wgsl`.
pub const STREAM_SKELETON: Source = Source { name: "stream_skeleton.wgsl", text: include_str!("stream_skeleton.wgsl") };

/// `triangle_moller_trumbore.wgsl`.
pub const TRIANGLE_MOLLER_TRUMBORE: Source =
    Source { name: "triangle_moller_trumbore.wgsl", text: include_str!("triangle_moller_trumbore.wgsl") };

/// `triangle_watertight.wgsl`.
pub const TRIANGLE_WATERTIGHT: Source =
    Source { name: "triangle_watertight.wgsl", text: include_str!("triangle_watertight.wgsl") };

/// `wide.wgsl`.
pub const WIDE: Source = Source { name: "wide.wgsl", text: include_str!("wide.wgsl") };

/// `wide_packet.wgsl`.
pub const WIDE_PACKET: Source = Source { name: "wide_packet.wgsl", text: include_str!("wide_packet.wgsl") };

/// `wide_ray_stream.wgsl`.
pub const WIDE_RAY_STREAM: Source = Source { name: "wide_ray_stream.wgsl", text: include_str!("wide_ray_stream.wgsl") };

/// `wide_stack.wgsl`.
pub const WIDE_STACK: Source = Source { name: "wide_stack.wgsl", text: include_str!("wide_stack.wgsl") };

/// `wide_trail.wgsl`.
pub const WIDE_TRAIL: Source = Source { name: "wide_trail.wgsl", text: include_str!("wide_trail.wgsl") };

/// Every file, in name order.
pub const ALL: &[Source] = &[
    ALL_HITS,
    BOX,
    BVH_LEAF,
    BVH_PARENT_SIBLING,
    BVH_REGISTER,
    BVH_REGISTER_RUN,
    BVH_RESUME,
    BVH_STACK,
    DISPATCH_GRID,
    DISPATCH_PERSISTENT,
    ENTRY,
    FALLBACK_HASH,
    FALLBACK_UNCLE,
    HASH,
    KD_COMMON,
    KD_PACKET,
    KD_RESTART,
    KD_STACK,
    KEYS32,
    KEYS64,
    LOOP_GUARD,
    NEAREST,
    NUMERICS,
    PRELUDE,
    PROBE,
    QUERY,
    RECORD,
    STREAM_COMMON,
    STREAM_COMPACT,
    STREAM_CULL,
    STREAM_EXPAND,
    STREAM_FILL,
    STREAM_FRUSTUM,
    STREAM_GATHER,
    STREAM_HEADS,
    STREAM_INTERSECT,
    STREAM_KEYS,
    STREAM_LEVELS,
    STREAM_PACKET_COUNTS,
    STREAM_PAIR_SCATTER,
    STREAM_RADIX_COUNT,
    STREAM_RADIX_SCATTER,
    STREAM_RANGES,
    STREAM_ROOTS_FLAG,
    STREAM_ROOTS_SCATTER,
    STREAM_SCAN,
    STREAM_SCAN_ADD,
    STREAM_SEGSCAN,
    STREAM_SEGSCAN_ADD,
    STREAM_SIZES,
    STREAM_SKELETON,
    TRIANGLE_MOLLER_TRUMBORE,
    TRIANGLE_WATERTIGHT,
    WIDE,
    WIDE_PACKET,
    WIDE_RAY_STREAM,
    WIDE_STACK,
    WIDE_TRAIL,
];

/// The file of `name` (for example `"box.wgsl"`), if there is one.
pub fn by_name(name: &str) -> Option<Source> {
    ALL.iter().copied().find(|s| s.name == name)
}

#[cfg(test)]
mod tests {
    /// Kernels take absolute values through `abs_bits` (numerics.wgsl): on an H100 the float
    /// built-in, or the minimum after it, flushed a subnormal to zero where the CPU keeps it.
    #[test]
    fn no_kernel_calls_the_float_abs_builtin() {
        for s in super::ALL {
            for (n, line) in s.text.lines().enumerate() {
                let code = line.split("//").next().unwrap_or("");
                let call = code
                    .match_indices("abs(")
                    .any(|(i, _)| !code[..i].ends_with(|c: char| c.is_alphanumeric() || c == '_'));
                assert!(!call, "{}:{}: the float abs built-in (use abs_bits): {line}", s.name, n + 1);
            }
        }
    }

    #[test]
    fn every_file_is_listed_once_and_found_by_name() {
        for s in super::ALL {
            assert!(!s.text.is_empty(), "{} is empty", s.name);
            assert_eq!(super::by_name(s.name), Some(*s));
        }
        assert_eq!(super::by_name("missing.wgsl"), None);
    }
}
