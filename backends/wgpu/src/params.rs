//! The uniform block every kernel reads (`Params` in shaders/prelude.wgsl).

use bytemuck::{Pod, Zeroable};

/// Per-batch and per-scene constants, laid out as the WGSL struct (128 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct Params {
    pub ray_count: u32,
    pub row_width: u32,
    pub root: u32,
    pub max_steps: u32,
    pub scene_scale: f32,
    /// Always 0; the shaders' opaque zero (see NUMERICS.md).
    pub zero: u32,
    pub d_mask: u32,
    pub h: u32,
    pub leaf_base: u32,
    pub record_stride: u32,
    pub record_cap: u32,
    pub short_stack: u32,
    pub kd_prims: u32,
    pub kd_tris: u32,
    pub wide_root_count: u32,
    /// Persistent threads: the most rounds a workgroup fetches.
    pub persistent_rounds: u32,
    pub kd_lo: [f32; 4],
    pub kd_hi: [f32; 4],
    /// The stream kernel: which round of a batch this is (0: the streams start), and the steps
    /// a stream takes in one round before it saves its state for the next.
    pub stream_round: u32,
    pub stream_steps: u32,
    /// The all-hits kernel: hits a list keeps (the caller's limit and one more), and whether hits
    /// at one `t` count once (1) or not (0).
    pub all_hits_keep: u32,
    pub all_hits_merge: u32,
    /// Invocations per work item (0 and 1: one; see [`crate::batch`]'s retry of a batch whose
    /// loops were cut): only every `item_spread`-th invocation takes an item.
    pub item_spread: u32,
    pub pad: [u32; 3],
}

#[cfg(test)]
mod tests {
    #[test]
    fn params_match_the_wgsl_size() {
        assert_eq!(core::mem::size_of::<super::Params>(), 128);
    }
}
