//! The wgpu kernels a scene's choices compile, against every kernel the backend could compile.

use raytrail_core::key::KeyWidth;
use raytrail_core::method::{Method, Query};
use raytrail_core::trace::{Record, TriangleTestKind};
use raytrail_wgpu::compose::{all_variants, Answer, DispatchKind, Variant};
use raytrail_wgpu::GpuConfig;

/// The kernels tracing compiles for `chosen` (a method per query) on a tree with `keys`: one per
/// distinct method and query, watertight, recording nothing, with the default dispatch. The wgpu
/// backend compiles a kernel the first time a trace asks for it, so these are also the ones worth
/// compiling ahead of time.
pub fn variants_for(keys: KeyWidth, chosen: &[(Method, Query)]) -> Vec<Variant> {
    let config = GpuConfig::default();
    let mut out: Vec<Variant> = Vec::new();
    for &(method, query) in chosen {
        let v = Variant {
            method,
            keys,
            triangle: TriangleTestKind::Watertight,
            query,
            record: Record::Nothing,
            dispatch: DispatchKind::of(config.dispatch, method),
            workgroup_size: config.workgroup_size,
            answer: Answer::Hit,
        };
        if !out.contains(&v) {
            out.push(v);
        }
    }
    out
}

/// How many kernels the backend could compile for a tree with `keys` (every method, triangle
/// test, query, recording and dispatch).
pub fn all_variant_count(keys: KeyWidth) -> usize {
    all_variants(keys).count()
}

/// Bytes of WGSL source the variants take to compile (what the shader compiler reads); a
/// variant that cannot be composed counts nothing.
pub fn source_bytes(variants: &[Variant]) -> usize {
    variants.iter().map(|v| v.source().map_or(0, |s| s.len())).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail_core::method::{KdMethod, WideMethod};

    #[test]
    fn one_kernel_per_distinct_method_and_query() {
        let bvh8 = Method::Wide(WideMethod::BVH8);
        let kd = Method::Kd(KdMethod::Stack);
        let chosen = [
            (kd, Query::Closest),
            (bvh8, Query::Any),
            (bvh8, Query::Any),
            (bvh8, Query::Closest),
            (kd, Query::Closest),
        ];
        let v = variants_for(KeyWidth::W32, &chosen);
        assert_eq!(v.len(), 3);
        assert!(v.iter().all(|v| v.keys == KeyWidth::W32 && v.record == Record::Nothing));
        assert!(all_variant_count(KeyWidth::W32) > 100 * v.len());
        assert!(source_bytes(&v) > 0);
        assert!(variants_for(KeyWidth::W64, &[]).is_empty());
    }
}
