use crate::geometry::Triangle;
use bytemuck::{Pod, Zeroable};

/// Triangles per [`TriangleBlock`].
pub const BLOCK: usize = 4;

/// Four triangles as a structure of arrays, for testing them at once: `v[vertex][axis][lane]`.
/// Lanes without a triangle hold NaN vertices, which no test hits.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct TriangleBlock {
    /// Vertex coordinates by vertex, axis and lane.
    pub v: [[[f32; BLOCK]; 3]; 3],
}

// SAFETY: `repr(C)` arrays of `f32`: no padding, every bit pattern valid.
unsafe impl Zeroable for TriangleBlock {}
// SAFETY: as above.
unsafe impl Pod for TriangleBlock {}

impl TriangleBlock {
    /// A block of up to four triangles (the rest of the lanes empty).
    pub fn new(triangles: &[Triangle]) -> TriangleBlock {
        let mut b = TriangleBlock { v: [[[f32::NAN; BLOCK]; 3]; 3] };
        for (lane, t) in triangles.iter().take(BLOCK).enumerate() {
            for (vertex, p) in t.v.iter().enumerate() {
                for axis in 0..3 {
                    b.v[vertex][axis][lane] = p[axis];
                }
            }
        }
        b
    }

    /// The vertices of `lane`, as a single-triangle test reads them.
    #[inline(always)]
    pub fn lane(&self, lane: usize) -> [[f32; 3]; 3] {
        core::array::from_fn(|vertex| core::array::from_fn(|axis| self.v[vertex][axis][lane]))
    }
}

/// The answers for the four lanes of a [`TriangleBlock`]: a mask of the lanes hit, and each hit
/// lane's [`TriangleHit`](super::TriangleHit) fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockHits {
    /// Bit `i` set where lane `i` is hit.
    pub mask: u32,
    /// Ray parameter per lane (meaningful where `mask` is set).
    pub t: [f32; BLOCK],
    /// Barycentric weight of the second vertex per lane.
    pub u: [f32; BLOCK],
    /// Barycentric weight of the third vertex per lane.
    pub v: [f32; BLOCK],
}

impl BlockHits {
    /// No lane hit.
    pub const NONE: BlockHits = BlockHits { mask: 0, t: [0.0; BLOCK], u: [0.0; BLOCK], v: [0.0; BLOCK] };

    /// Sets `lane` to `hit` (or clears it).
    #[inline(always)]
    pub fn set(&mut self, lane: usize, hit: Option<super::TriangleHit>) {
        match hit {
            Some(h) => {
                self.mask |= 1 << lane;
                (self.t[lane], self.u[lane], self.v[lane]) = (h.t, h.u, h.v);
            }
            None => self.mask &= !(1 << lane),
        }
    }

    /// Lane `lane`'s hit, if it has one.
    #[inline(always)]
    pub fn get(&self, lane: usize) -> Option<super::TriangleHit> {
        (self.mask & (1 << lane) != 0).then(|| super::TriangleHit { t: self.t[lane], u: self.u[lane], v: self.v[lane] })
    }
}
