//! A scene of instances: bottom-level prepared meshes placed by transforms, and a top-level BVH
//! over their world boxes.

use super::transform::{ToObject, Transform};
use crate::bvh2::{Bvh2, SahBuilder, SahConfig};
use crate::prepared::PreparedScene;
use crate::trace::Trace;
use crate::{Aabb, Error};
use alloc::sync::Arc;
use alloc::vec::Vec;

/// One placement of a mesh: which mesh, where, the id its hits carry and the mask rays are
/// tested against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// Index of the mesh among the scene's meshes.
    pub mesh: u32,
    /// From the mesh's frame to the world.
    pub transform: Transform,
    /// The id [`InstanceHit::instance`](super::InstanceHit::instance) reports for its hits.
    pub id: u32,
    /// A ray enters the instance only where `ray_mask & mask != 0` (all bits set: every ray).
    pub mask: u32,
}

impl Instance {
    /// Mesh `mesh` placed by `transform`, with id `0` and every mask bit set.
    pub fn new(mesh: u32, transform: Transform) -> Self {
        Self { mesh, transform, id: 0, mask: u32::MAX }
    }

    /// The same instance with id `id`.
    pub fn with_id(self, id: u32) -> Self {
        Self { id, ..self }
    }

    /// The same instance with mask `mask`.
    pub fn with_mask(self, mask: u32) -> Self {
        Self { mask, ..self }
    }
}

/// Instances of prepared meshes, ready to trace with one backend (its prepared form `P` of each
/// mesh), with a top-level BVH over the instances' world boxes.
pub struct InstancedScene<P> {
    meshes: Vec<P>,
    instances: Vec<Instance>,
    /// Per instance, its inverse map.
    pub(super) to_object: Vec<ToObject>,
    /// Per instance, a superset of where it can be hit ([`Transform::world_box`]).
    pub(super) world_boxes: Vec<Aabb>,
    /// Over the world boxes; its primitive ids are instance indices.
    pub(super) top: Bvh2,
}

impl<P> core::fmt::Debug for InstancedScene<P> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("InstancedScene")
            .field("meshes", &self.meshes.len())
            .field("instances", &self.instances.len())
            .finish_non_exhaustive()
    }
}

impl<P> InstancedScene<P> {
    /// `instances` of `meshes`, each mesh prepared by `backend` once however many instances it
    /// has.
    ///
    /// Errors: [`Error::EmptyScene`] without instances, [`Error::InvalidInstance`] for an
    /// instance whose mesh index is out of range or whose transform is not finite or not
    /// invertible, and whatever `backend` reports preparing a mesh.
    pub fn prepare<B: Trace<Prepared = P>>(
        backend: &B,
        meshes: &[Arc<PreparedScene>],
        instances: &[Instance],
    ) -> Result<Self, Error> {
        if instances.is_empty() {
            return Err(Error::EmptyScene);
        }
        let mut to_object = Vec::with_capacity(instances.len());
        let mut world_boxes = Vec::with_capacity(instances.len());
        for (index, inst) in instances.iter().enumerate() {
            let mesh = meshes
                .get(inst.mesh as usize)
                .ok_or(Error::InvalidInstance { index, why: "its mesh index is not among the scene's meshes" })?;
            let inverse = inst
                .transform
                .inverse()
                .ok_or(Error::InvalidInstance { index, why: "its transform is not finite or not invertible" })?;
            to_object.push(inverse);
            world_boxes.push(inst.transform.world_box(&mesh.bounds()));
        }
        let top = SahBuilder::new(SahConfig { max_leaf_size: 1, ..SahConfig::default() }).build_boxes(&world_boxes)?;
        let meshes = meshes.iter().map(|m| backend.prepare(m.clone())).collect::<Result<Vec<_>, _>>()?;
        Ok(Self { meshes, instances: instances.to_vec(), to_object, world_boxes, top })
    }

    /// The instances, in the order given.
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }

    /// The meshes in the backend's form.
    pub fn meshes(&self) -> &[P] {
        &self.meshes
    }

    /// The world box of instance `index` (a superset of its mapped mesh).
    pub fn world_box(&self, index: usize) -> Option<Aabb> {
        self.world_boxes.get(index).copied()
    }
}
