//! What the stream method's kernels share: the stream constants after the core's, and
//! `stream_common.wgsl`; with the intersection kernel's own files. Apart from the stages'
//! composition ([`super::compose`]) because the intersection kernel is also a [`Variant`] of the
//! general composition ([`crate::compose`]), which takes these from here.
//!
//! [`Variant`]: crate::compose::Variant

use raytrail_core::stream::frustum::{MARGIN, NO_AXIS};

/// A WGSL file: name and text.
pub(crate) type Part = (&'static str, &'static str);

/// `stream_common.wgsl`: every stream kernel's buffers and helpers.
pub(crate) const STREAM_COMMON: Part = (raytrail_shaders::STREAM_COMMON.name, raytrail_shaders::STREAM_COMMON.text);

/// `stream_levels.wgsl`: the level-order tree, read by the expansion and the intersection.
pub(crate) const STREAM_LEVELS: Part = (raytrail_shaders::STREAM_LEVELS.name, raytrail_shaders::STREAM_LEVELS.text);

/// The intersection kernel's own files, after the wide methods' files and [`STREAM_COMMON`].
pub(crate) const INTERSECT_OWN: [Part; 2] =
    [STREAM_LEVELS, (raytrail_shaders::STREAM_INTERSECT.name, raytrail_shaders::STREAM_INTERSECT.text)];

/// The stream method's constants, written from the core's values, to follow the core's header.
pub(crate) fn stream_header() -> String {
    format!(
        "// The stream method's constants, from raytrail-core.\n\
         const STREAM_MARGIN_BITS: u32 = {:#010x}u;\n\
         const NO_AXIS: u32 = {NO_AXIS}u;\n",
        MARGIN.to_bits()
    )
}
