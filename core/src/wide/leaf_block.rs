use crate::intersect::{TriangleBlock, BLOCK};
use bytemuck::{Pod, Zeroable};

/// Four triangles of a wide tree's leaf and their primitive ids in one record, as the CPU reads
/// them: the id of a lane the ray hits is read from the lines the block's test has just loaded,
/// where a separate array of ids costs a load from elsewhere per hit (on the dragon, a likely
/// miss). Aligned to 32 bytes, a record spans three cache lines wherever it lies (a 144-byte block
/// at 16-byte alignment spans three or four). 1.02-1.06 on the dragon's rays, 0.99-1.03 on the
/// interiors' (`docs/notes/*-benchmarks-leaf-blocks.md`, "Triangle blocks that carry their primitive ids").
///
/// Byte layout (`repr(C)`, 160 bytes, no padding): `triangles` (144 bytes, [`TriangleBlock`]'s
/// layout), then `prims` (16 bytes). Lanes without a triangle hold NaN vertices and id
/// `u32::MAX`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct LeafBlock {
    /// The four triangles, by vertex, axis and lane.
    pub triangles: TriangleBlock,
    /// The primitive id of each lane.
    pub prims: [u32; BLOCK],
}

// SAFETY: `repr(C)` of a `Pod` block of 144 bytes and four `u32`s: 160 bytes, a multiple of the
// 32-byte alignment, so there is no padding, and every bit pattern is a valid value.
unsafe impl Zeroable for LeafBlock {}
// SAFETY: as above; the type is `Copy + 'static`.
unsafe impl Pod for LeafBlock {}

impl LeafBlock {
    /// A block of up to four `triangles` with their primitive ids `prims`, by lane: lanes past
    /// `triangles` are empty, and a triangle without an id gets `u32::MAX`.
    pub fn new(triangles: &[crate::geometry::Triangle], prims: &[u32]) -> LeafBlock {
        LeafBlock {
            triangles: TriangleBlock::new(triangles),
            prims: core::array::from_fn(|lane| {
                if lane < triangles.len() {
                    prims.get(lane).copied().unwrap_or(u32::MAX)
                } else {
                    u32::MAX
                }
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_leaf_block_is_160_bytes_at_32_byte_alignment() {
        assert_eq!((core::mem::size_of::<LeafBlock>(), core::mem::align_of::<LeafBlock>()), (160, 32));
    }
}
