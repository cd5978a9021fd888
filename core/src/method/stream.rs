use core::fmt;

/// A ray-stream method (Garanzha & Loop 2010): the batch is traced as a whole, not ray by ray.
///
/// The rays are hashed and sorted into coherent packets, one frustum bounds each packet, the
/// frustums traverse an 8-wide BVH breadth-first (a level at a time, compacted by a scan), and
/// each packet's rays are then intersected with the leaves its frustum reached, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum StreamMethod {
    /// Sorted packets, breadth-first frustum traversal of the 8-wide tree stored level by level,
    /// localized intersection. Pick it for whole batches of coherent rays (camera rays inside
    /// rooms); it gains nothing on rays in no order.
    Frustum8,
}

impl StreamMethod {
    /// Every stream method.
    pub const ALL: [StreamMethod; 1] = [StreamMethod::Frustum8];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            StreamMethod::Frustum8 => "stream",
        }
    }

    /// Per-ray state in bytes during localized intersection: the closest hit so far (`t` and
    /// primitive) and the position in the packet's leaf list. The packet's frustum and leaf list
    /// are shared by its rays and counted in [`StreamStats`](crate::stream::StreamStats) instead.
    pub fn state_bytes(self) -> usize {
        4 + 4 + 4
    }
}

impl fmt::Display for StreamMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
