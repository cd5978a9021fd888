//! A stack of parallel, nearly coincident triangles that drives the binned SAH builder into a
//! chain deeper than 31 levels, so the tree needs 64-bit keys (and its 4-wide tree too).

use super::scene_of;
use crate::rng::Pcg32;
use glam::Vec3;
use raytrail_core::geometry::Triangle;
use raytrail_core::scene::Scene;

/// Layers per group: the SAH builder's default leaf block ([`SahConfig::leaf_block`](raytrail_core::bvh2::SahConfig::leaf_block); a test
/// checks the depth this gives).
const GROUP: usize = 4;

/// Layers of the suite's stack: the SAH tree is `(layers - 8) / 4` deep (52), past the 31 levels
/// of 32-bit keys and inside the 63 of 64-bit ones; its 4-wide pull-up is 18 deep, past the 15
/// levels of 32-bit 4-wide keys (two bits per level), so `bvh4-hash` runs on 64-bit keys too.
pub const DEFAULT_LAYERS: usize = 216;

/// Most layers: a tree of depth 63.
pub const MAX_LAYERS: usize = 8 + GROUP * 63;

/// Gap between the two lowest groups of layers. The stack is at most 8 such gaps thick (2^-57),
/// far below `f32::EPSILON` relative to its unit extent in y and z, so every box's surface area
/// rounds to exactly 1, in `f32` and in `f64` alike.
const FIRST_GAP: f64 = 1.0 / (1u64 << 60) as f64;

/// Each gap between groups is this fraction of the one below it.
const GAP_RATIO: f64 = 7.0 / 8.0;

/// Layers of a group are this fraction of the group's gap apart (64 ulps of `f32` at the top of
/// the stack, so they stay distinct).
const LAYER_SPACING: f64 = 1.0 / 64.0;

/// `layers` unit right triangles in the planes `x = p_m`, stacked along x in groups of four, in
/// a shuffled primitive order.
///
/// Why it is deep: every box of the stack spans `[0, 1]` in y and z and less than 2^-57 in x, so
/// all surface areas are exactly 1, and a split's SAH cost is the number of four-triangle leaf
/// tests of its two sides (the builder's default [`SahConfig::leaf_block`](raytrail_core::bvh2::SahConfig::leaf_block)). Splitting off one
/// group of four costs the least any split can, so the binned builder takes it when it is the
/// first candidate: the gaps between groups shrink by 7/8 from the bottom up, so the lowest group
/// always lies in bin 0, alone. Each split peels off one group, down to the 8-triangle leaf.
///
/// Rays through the stack meet all layers at (in `f32`) the same `t`, so the closest hit is
/// decided by the smaller primitive id; the shuffle makes that differ from the geometric order.
/// Panics if `layers` is 0 or over [`MAX_LAYERS`] (the builder caps depth at 63).
pub fn degenerate_stack(layers: usize, seed: u64) -> Scene {
    assert!((1..=MAX_LAYERS).contains(&layers), "degenerate_stack: layers must be in 1..={MAX_LAYERS}, got {layers}");
    let mut tris = Vec::with_capacity(layers);
    let (mut p, mut gap) = (0.0f64, FIRST_GAP);
    for m in 0..layers {
        let x = (p + (m % GROUP) as f64 * LAYER_SPACING * gap) as f32;
        let (a, b, c) = (Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0), Vec3::new(x, 0.0, 1.0));
        // Alternate the winding so front and back faces both occur.
        tris.push(if m % 2 == 0 { Triangle::new(a, b, c) } else { Triangle::new(a, c, b) });
        if m % GROUP == GROUP - 1 {
            p += gap;
            gap *= GAP_RATIO;
        }
    }
    Pcg32::new(seed, 0x57ac).shuffle(&mut tris);
    scene_of(tris)
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail_core::bvh2::SahBuilder;
    use raytrail_core::key::KeyWidth;

    #[test]
    fn sah_tree_is_deeper_than_32_bit_keys_allow() {
        let scene = degenerate_stack(DEFAULT_LAYERS, 1);
        let stats = SahBuilder::default().build(scene.triangles()).unwrap().stats();
        assert!(stats.depth > 31 && stats.depth <= 63, "depth {}", stats.depth);
        assert_eq!(stats.depth as usize, (DEFAULT_LAYERS - 8) / GROUP);
        assert_eq!(GROUP as u32, raytrail_core::bvh2::SahConfig::default().leaf_block);
        assert_eq!(stats.key_width, KeyWidth::W64);
    }

    #[test]
    fn layers_are_distinct_and_ordered() {
        let scene = degenerate_stack(DEFAULT_LAYERS, 1);
        let mut xs: Vec<f32> = scene.triangles().iter().map(|t| t.v[0].x).collect();
        xs.sort_by(f32::total_cmp);
        assert!(xs.windows(2).all(|w| w[0] < w[1]));
        assert!(xs[DEFAULT_LAYERS - 1] < 2f32.powi(-56));
        let deepest = SahBuilder::default().build(degenerate_stack(MAX_LAYERS, 1).triangles()).unwrap().stats();
        assert_eq!(deepest.depth, 63);
    }
}
