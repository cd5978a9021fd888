use crate::Error;

/// The largest packet: a packet's frustum is built by one GPU invocation looping over its rays
/// twice, and a shader's loops must stay well short of what a driver allows (Mesa's lavapipe was
/// seen to stop them after about 32,768 iterations in all). The paper's packets hold at most 512.
pub const MAX_PACKET: u32 = 8192;

/// The stream method's parameters (Garanzha & Loop 2010, Sec. 3.1 and 5.1). Compared and hashed
/// by the bits of the fractions.
#[derive(Clone, Copy, Debug)]
pub struct StreamParams {
    /// Origin cell size as a fraction of the scene box's diagonal (the paper's UserCellFraction;
    /// 0.004 by default, its robust choice).
    pub origin_cell_fraction: f32,
    /// Direction cell size as a fraction of a cube face's side: directions are quantized on the
    /// face of the unit cube they point through, so the rays of one cell share their dominant
    /// axis (the frustum's). 1/16 by default.
    pub direction_cell_fraction: f32,
    /// Most rays per packet (the paper's MaxSize; 256 by default; at most [`MAX_PACKET`]).
    pub max_packet: u32,
    /// Leaf lists longer than this are intersected in pieces of this many leaves, in parallel,
    /// and merged by the closest-hit rule (the paper's remedy for a frustum that captures most
    /// leaves, Sec. 5.5); 8192 by default.
    pub split_leaves: u32,
}

impl Default for StreamParams {
    fn default() -> Self {
        Self { origin_cell_fraction: 0.004, direction_cell_fraction: 1.0 / 16.0, max_packet: 256, split_leaves: 8192 }
    }
}

impl StreamParams {
    /// Checks that the cell fractions are positive and finite and the packet size is at least 1.
    pub fn check(&self) -> Result<(), Error> {
        let fraction_ok = |f: f32| f.is_finite() && f > 0.0;
        if !fraction_ok(self.origin_cell_fraction) {
            return Err(Error::InvalidParameter { name: "origin cell fraction", why: "must be positive and finite" });
        }
        if !fraction_ok(self.direction_cell_fraction) {
            return Err(Error::InvalidParameter {
                name: "direction cell fraction",
                why: "must be positive and finite",
            });
        }
        if self.max_packet == 0 || self.max_packet > MAX_PACKET {
            return Err(Error::InvalidParameter { name: "packet size", why: "must be between 1 and 8192" });
        }
        if self.split_leaves == 0 {
            return Err(Error::InvalidParameter { name: "leaf-list piece size", why: "must be at least 1" });
        }
        Ok(())
    }
}

impl StreamParams {
    fn bits(&self) -> (u32, u32, u32, u32) {
        (
            self.origin_cell_fraction.to_bits(),
            self.direction_cell_fraction.to_bits(),
            self.max_packet,
            self.split_leaves,
        )
    }
}

impl PartialEq for StreamParams {
    fn eq(&self, other: &Self) -> bool {
        self.bits() == other.bits()
    }
}

impl Eq for StreamParams {}

impl core::hash::Hash for StreamParams {
    fn hash<H: core::hash::Hasher>(&self, state: &mut H) {
        self.bits().hash(state);
    }
}
