//! The one convention for naming what a traversal visited, whatever backend recorded it.

use super::PreparedScene;
use crate::bvh2::NodeRef;
use crate::method::Method;
use crate::Error;
use alloc::vec::Vec;

/// The id [`PreparedScene::canonical_ids`] gives a recorded reference that names no node of the
/// tree (only damaged tables produce one).
pub const UNKNOWN_NODE: u32 = u32::MAX;

impl PreparedScene {
    /// Canonical ids of one ray's recorded node references, in visiting order: for BVH2 methods
    /// the node's index in the canonical tree, whatever layout was traversed; for kd methods the
    /// leaves alone, by index (restarting methods revisit inner nodes, so the leaf sequence is
    /// what all kd methods share); for wide methods the canonical id of the binary node each wide
    /// node or leaf stands for. Every backend turns its recordings into enumerations here.
    pub fn canonical_ids(&self, method: Method, refs: impl IntoIterator<Item = NodeRef>) -> Result<Vec<u32>, Error> {
        match method {
            Method::Bvh2(m) => {
                let layout = self.layout(m)?;
                Ok(refs.into_iter().map(|r| layout.canonical_id(r).unwrap_or(UNKNOWN_NODE)).collect())
            }
            Method::Kd(_) => Ok(refs.into_iter().filter(|r| r.is_leaf()).map(|r| r.offset()).collect()),
            // Wide nodes and leaves by the binary node each stands for.
            Method::Wide(m) => {
                let tree = self.wide_tree(m)?;
                Ok(refs.into_iter().map(|r| tree.canonical_id(r).unwrap_or(UNKNOWN_NODE)).collect())
            }
            // A stream method's enumeration is made by its pipeline (its packets' leaf lists).
            Method::Stream(m) => {
                Err(Error::Unsupported { method: m.name(), by: "per-ray recordings (its pipeline enumerates)" })
            }
        }
    }
}
