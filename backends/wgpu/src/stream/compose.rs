//! Which WGSL files make each kernel of the stream method.
//!
//! Every stream kernel is composed over the prelude, numerics and box files (the ray type, the
//! opaque zero, `div_rn`, the slab test) and `stream_common.wgsl`; the intersection kernel adds the
//! triangle test, query, recording and wide.wgsl's leaf test, as the wide methods' kernels do.

use super::shared_parts::{stream_header, Part, INTERSECT_OWN, STREAM_COMMON, STREAM_LEVELS};
use crate::compose::{constants_header, Answer, Variant};
use raytrail_core::key::KeyWidth;
use raytrail_core::method::{Method, StreamMethod};
use raytrail_core::trace::{Record, TraceOptions};
use raytrail_core::Error;

macro_rules! part {
    ($source:ident) => {
        (raytrail_shaders::$source.name, raytrail_shaders::$source.text)
    };
}

/// One kernel of the stream pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum StreamKernel {
    Keys,
    Heads,
    Compact,
    Sizes,
    Scan,
    ScanAdd,
    SegScan,
    SegScanAdd,
    RadixCount,
    RadixScatter,
    Fill,
    Gather,
    Skeleton,
    PacketCounts,
    Frustum,
    RootsFlag,
    RootsScatter,
    Expand,
    PairScatter,
    Ranges,
    /// Localized intersection, specialized like the other methods' kernels.
    Intersect(Variant),
}

impl StreamKernel {
    /// Every kernel but the intersection (which [`crate::compose::all_variants`] covers).
    pub(crate) const STAGES: [StreamKernel; 20] = [
        StreamKernel::Keys,
        StreamKernel::Heads,
        StreamKernel::Compact,
        StreamKernel::Sizes,
        StreamKernel::Scan,
        StreamKernel::ScanAdd,
        StreamKernel::SegScan,
        StreamKernel::SegScanAdd,
        StreamKernel::RadixCount,
        StreamKernel::RadixScatter,
        StreamKernel::Fill,
        StreamKernel::Gather,
        StreamKernel::Skeleton,
        StreamKernel::PacketCounts,
        StreamKernel::Frustum,
        StreamKernel::RootsFlag,
        StreamKernel::RootsScatter,
        StreamKernel::Expand,
        StreamKernel::PairScatter,
        StreamKernel::Ranges,
    ];

    /// The intersection kernel a trace with `options` runs: one per triangle test, query and
    /// whether counters are kept (the key width does not matter to it).
    pub(crate) fn intersect(method: StreamMethod, options: &TraceOptions) -> StreamKernel {
        let record = if options.record == Record::Nothing { Record::Nothing } else { Record::Counters };
        StreamKernel::Intersect(Variant {
            method: method.into(),
            keys: KeyWidth::W32,
            triangle: options.triangle_test,
            query: options.query,
            record,
            // Its own entry point: these two are not used.
            dispatch: Default::default(),
            workgroup_size: crate::GpuConfig::default().workgroup_size,
            answer: Answer::Hit,
        })
    }

    /// The kernel's name, for labels.
    pub(crate) fn label(&self) -> String {
        match self {
            StreamKernel::Intersect(v) => format!("stream-intersect/{}", v.label()),
            other => format!("stream-{other:?}"),
        }
    }

    /// The kernel's own files, after the common ones.
    fn own_parts(&self) -> Vec<Part> {
        let levels = STREAM_LEVELS;
        match self {
            StreamKernel::Keys => vec![part!(STREAM_KEYS)],
            StreamKernel::Heads => vec![part!(STREAM_HEADS)],
            StreamKernel::Compact => vec![part!(STREAM_COMPACT)],
            StreamKernel::Sizes => vec![part!(STREAM_SIZES)],
            StreamKernel::Scan => vec![part!(STREAM_SCAN)],
            StreamKernel::ScanAdd => vec![part!(STREAM_SCAN_ADD)],
            StreamKernel::SegScan => vec![part!(STREAM_SEGSCAN)],
            StreamKernel::SegScanAdd => vec![part!(STREAM_SEGSCAN_ADD)],
            StreamKernel::RadixCount => vec![part!(STREAM_RADIX_COUNT)],
            StreamKernel::RadixScatter => vec![part!(STREAM_RADIX_SCATTER)],
            StreamKernel::Fill => vec![part!(STREAM_FILL)],
            StreamKernel::Gather => vec![part!(STREAM_GATHER)],
            StreamKernel::Skeleton => vec![part!(STREAM_SKELETON)],
            StreamKernel::PacketCounts => vec![part!(STREAM_PACKET_COUNTS)],
            StreamKernel::Frustum => vec![part!(STREAM_FRUSTUM)],
            StreamKernel::RootsFlag => vec![part!(STREAM_ROOTS_FLAG)],
            StreamKernel::RootsScatter => vec![part!(STREAM_ROOTS_SCATTER)],
            StreamKernel::Expand => vec![levels, part!(STREAM_CULL), part!(STREAM_EXPAND)],
            StreamKernel::PairScatter => vec![part!(STREAM_PAIR_SCATTER)],
            StreamKernel::Ranges => vec![part!(STREAM_RANGES)],
            StreamKernel::Intersect(_) => INTERSECT_OWN.to_vec(),
        }
    }

    /// The files of the kernel, in order (the intersection kernel's as its [`Variant`] composes
    /// them).
    pub(crate) fn parts(&self) -> Result<Vec<Part>, Error> {
        if let StreamKernel::Intersect(v) = self {
            return v.parts();
        }
        let mut parts = vec![part!(PRELUDE), part!(NUMERICS), part!(BOX), STREAM_COMMON];
        parts.extend(self.own_parts());
        Ok(parts)
    }

    /// The full source: the generated constants, then the files.
    pub(crate) fn source(&self) -> Result<String, Error> {
        if let StreamKernel::Intersect(v) = self {
            return v.source();
        }
        let mut s = constants_header(Method::Stream(StreamMethod::Frustum8));
        s.push_str(&stream_header());
        for (name, text) in self.parts()? {
            s.push_str(&format!("\n// ---- shaders/{name} ----\n"));
            s.push_str(text);
        }
        Ok(s)
    }

    /// Override constants: the intersection's query and recording (counters at most: the
    /// method's enumeration is built on the host from the traversal's arrays).
    pub(crate) fn overrides(&self) -> Vec<(&'static str, f64)> {
        match self {
            StreamKernel::Intersect(v) => {
                let record = if v.record == Record::Nothing { Record::Nothing } else { Record::Counters };
                Variant { record, ..*v }.method_overrides()
            }
            _ => Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_stage_kernel_parses_and_validates_without_an_adapter() {
        let mut failures = Vec::new();
        for k in StreamKernel::STAGES {
            let src = k.source().expect("composes");
            let checked = naga::front::wgsl::parse_str(&src).map_err(|e| e.emit_to_string(&src)).and_then(|m| {
                naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::FLOAT64)
                    .validate(&m)
                    .map(|_| ())
                    .map_err(|e| e.emit_to_string(&src))
            });
            if let Err(e) = checked {
                failures.push(format!("{}:\n{e}", k.label()));
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }
}
