use bytemuck::{Pod, Zeroable};

/// The result of tracing one ray.
///
/// The layout (16 bytes: `t`, `prim`, `u`, `v`) is the one of the CLI's `.npy` hit files. A miss
/// has `t = +inf` and `prim = u32::MAX`; a ray the numerics cannot answer is refused
/// ([`Hit::REFUSED`]: `t` NaN, `prim = u32::MAX - 1`), never a miss.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Hit {
    /// Ray parameter of the hit point.
    pub t: f32,
    /// Primitive (triangle) index in file order.
    pub prim: u32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex.
    pub v: f32,
}

impl Hit {
    /// Primitive id of a miss.
    pub const NO_PRIM: u32 = u32::MAX;
    /// The miss.
    pub const MISS: Hit = Hit { t: f32::INFINITY, prim: Self::NO_PRIM, u: 0.0, v: 0.0 };
    /// Primitive id of a refused ray.
    pub const REFUSED_PRIM: u32 = u32::MAX - 1;
    /// The answer for a ray no method can answer reliably (see
    /// `PreparedScene::frame_rays`): `t` is NaN, so it is neither a hit nor a miss at any
    /// distance, and it is counted in the `Report`.
    pub const REFUSED: Hit = Hit { t: f32::NAN, prim: Self::REFUSED_PRIM, u: 0.0, v: 0.0 };

    /// Whether this is a hit (not a miss, not refused).
    #[inline(always)]
    pub fn is_hit(&self) -> bool {
        self.prim < Self::REFUSED_PRIM
    }

    /// Whether the ray was refused ([`Hit::REFUSED`]).
    #[inline(always)]
    pub fn is_refused(&self) -> bool {
        self.prim == Self::REFUSED_PRIM
    }

    /// Whether a candidate at `t` on primitive `prim` replaces this one as the closest.
    ///
    /// Ties at equal `t` go to the smaller primitive id, so the closest hit never depends on the
    /// order in which a method visits primitives.
    #[inline(always)]
    pub fn is_beaten_by(&self, t: f32, prim: u32) -> bool {
        t < self.t || (t == self.t && prim < self.prim)
    }

    /// The order of the closest-hit rule ([`Hit::is_beaten_by`]): the nearer first, at an equal
    /// `t` (`-0.0` equals `0.0`) the lower primitive id. A NaN `t` (a refused hit) is ordered
    /// as equal to everything by `t`, so by its id.
    pub fn order(&self, other: &Hit) -> core::cmp::Ordering {
        self.t.partial_cmp(&other.t).unwrap_or(core::cmp::Ordering::Equal).then(self.prim.cmp(&other.prim))
    }

    /// Whether two hits are identical bit for bit in `t` and `prim` (the conformance criterion).
    pub fn same_as(&self, other: &Hit) -> bool {
        self.prim == other.prim && self.t.to_bits() == other.t.to_bits()
    }
}

impl Default for Hit {
    fn default() -> Self {
        Self::MISS
    }
}
