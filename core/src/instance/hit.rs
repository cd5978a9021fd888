//! The answer for one ray in an instanced scene: a [`Hit`] with the instance it is on.

use crate::Hit;
use bytemuck::{Pod, Zeroable};

/// A hit in an instanced scene: the distance, the primitive of the instance's mesh, the
/// barycentrics (of the mesh's triangle, which a transform does not change) and the instance's
/// id ([`Instance::id`](super::Instance::id)) and position in the scene's list. 24 bytes, `repr(C)`.
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct InstanceHit {
    /// Distance along the world ray (the same along the ray mapped into the mesh's frame).
    pub t: f32,
    /// Primitive id within the instance's mesh ([`Hit::NO_PRIM`] for a miss,
    /// [`Hit::REFUSED_PRIM`] for a refusal).
    pub prim: u32,
    /// Barycentric coordinate of the second vertex.
    pub u: f32,
    /// Barycentric coordinate of the third vertex.
    pub v: f32,
    /// The id of the instance hit ([`InstanceHit::NO_INSTANCE`] for a miss or a refusal).
    pub instance: u32,
    /// The position of the instance hit in the scene's list (ties between instances resolve by
    /// it; `u32::MAX` for a miss or a refusal).
    pub index: u32,
}

impl InstanceHit {
    /// The instance id of a miss or a refusal.
    pub const NO_INSTANCE: u32 = u32::MAX;
    /// No hit.
    pub const MISS: InstanceHit = Self::from_hit(&Hit::MISS, u32::MAX, Self::NO_INSTANCE);
    /// A refused ray ([`Hit::REFUSED`]).
    pub const REFUSED: InstanceHit = Self::from_hit(&Hit::REFUSED, u32::MAX, Self::NO_INSTANCE);

    /// `hit` on the instance at `index` in the scene's list, whose id is `id`.
    pub const fn from_hit(hit: &Hit, index: u32, id: u32) -> Self {
        InstanceHit { t: hit.t, prim: hit.prim, u: hit.u, v: hit.v, instance: id, index }
    }

    /// The hit without its instance.
    pub fn hit(&self) -> Hit {
        Hit { t: self.t, prim: self.prim, u: self.u, v: self.v }
    }

    /// Whether this is a hit.
    pub fn is_hit(&self) -> bool {
        self.hit().is_hit()
    }

    /// Whether the ray was refused.
    pub fn is_refused(&self) -> bool {
        self.prim == Hit::REFUSED_PRIM
    }

    /// Whether `hit` on the instance at `index` replaces this one as the closest: nearer, or at
    /// an equal `t` on an instance listed earlier, or on the same instance with a smaller
    /// primitive id ([`Hit::is_beaten_by`] extended to instances).
    pub fn is_beaten_by(&self, hit: &Hit, index: u32) -> bool {
        !self.is_hit() || hit.t < self.t || (hit.t == self.t && (index, hit.prim) < (self.index, self.prim))
    }
}
