use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec3A};

/// A ray with its parametric interval: points `origin + t * dir` for `t` in `[tmin, tmax]`.
///
/// The memory layout (32 bytes: origin xyz, tmin, direction xyz, tmax) is the one of the CLI's
/// `.npy` ray files and of the GPU ray buffers.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Ray {
    /// Origin.
    pub origin: [f32; 3],
    /// Start of the interval.
    pub tmin: f32,
    /// Direction; need not be normalized.
    pub dir: [f32; 3],
    /// End of the interval; may be `+inf`.
    pub tmax: f32,
}

impl Ray {
    /// A ray over `[tmin, tmax]`.
    pub fn new(origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Self {
        Self { origin: origin.to_array(), tmin, dir: dir.to_array(), tmax }
    }

    /// Origin as a vector.
    #[inline(always)]
    pub fn origin(&self) -> Vec3 {
        Vec3::from_array(self.origin)
    }

    /// Direction as a vector.
    #[inline(always)]
    pub fn dir(&self) -> Vec3 {
        Vec3::from_array(self.dir)
    }

    /// Whether the ray can hit anything at all.
    ///
    /// Rays with a NaN or infinite origin or direction component, a zero direction, a NaN bound, or
    /// `tmin > tmax` are a documented miss: every method returns no hit for them without visiting a
    /// node.
    #[inline]
    pub fn is_traceable(&self) -> bool {
        let o = Vec3A::from_array(self.origin);
        let d = Vec3A::from_array(self.dir);
        // `x * 0` is ±0 for a finite `x` and NaN for an infinite or NaN one: one lane-wise test
        // for all six components. `tmin <= tmax` is false when either bound is NaN.
        let finite = (o * 0.0 + d * 0.0).cmpeq(Vec3A::ZERO).all();
        finite && d.cmpne(Vec3A::ZERO).any() && self.tmin <= self.tmax
    }

    /// 1 where [`Ray::is_traceable`] is false, else 0, worked on the bits without a branch, so
    /// that a pass counting a batch's untraceable rays costs about a nanosecond a ray: an exponent
    /// of all ones is an infinity or a NaN, a direction whose magnitude bits are all zero is zero.
    #[inline(always)]
    pub fn untraceable_flag(&self) -> u32 {
        let bits = |x: f32| x.to_bits();
        let non_finite = |x: f32| u32::from(bits(x) & 0x7f80_0000 == 0x7f80_0000);
        let bad = non_finite(self.origin[0])
            | non_finite(self.origin[1])
            | non_finite(self.origin[2])
            | non_finite(self.dir[0])
            | non_finite(self.dir[1])
            | non_finite(self.dir[2]);
        let dir = (bits(self.dir[0]) | bits(self.dir[1]) | bits(self.dir[2])) & 0x7fff_ffff;
        bad | u32::from(dir == 0) | (1 - u32::from(self.tmin <= self.tmax))
    }
}
