//! How the backend spreads a trace over the device: batch size, batches in flight, and how
//! invocations get their rays.

use crate::device::device_error;
use raytrail_core::method::Method;
use raytrail_core::method::WideWalk;
use raytrail_core::Error;

/// How a kernel's invocations get their work items (rays, or packets of rays).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Dispatch {
    /// Each method's own ([`Dispatch::for_method`]): persistent threads for the wide methods
    /// that keep a stack, a grid for the rest.
    #[default]
    ByMethod,
    /// One invocation per item over a grid as large as the batch: the hardware scheduler hands
    /// out workgroups.
    Grid,
    /// Persistent threads (Aila & Laine 2009): `workgroups` resident workgroups, each fetching
    /// the next workgroup-sized run of items from a global counter until the batch is done.
    Persistent {
        /// Workgroups launched; raised where needed so that no workgroup loops more than
        /// [`MAX_PERSISTENT_ROUNDS`] times ([`CPU_ADAPTER_ROUNDS`] on a CPU adapter).
        workgroups: u32,
    },
}

impl Dispatch {
    /// Persistent threads with the default number of workgroups.
    pub const PERSISTENT: Dispatch = Dispatch::Persistent { workgroups: DEFAULT_PERSISTENT_WORKGROUPS };

    /// The dispatch `method` runs under: this one, or for [`Dispatch::ByMethod`] persistent
    /// threads for the wide methods that keep a stack (bvh4, bvh8, bvh4-naive, bvh8-sah) and a
    /// grid for every other. On an H100 at 2M rays, bvh4 and bvh8 ran 1.0-3.1x faster with
    /// persistent threads than on the grid on all 8 scene and ray type pairs measured (bvh4-naive
    /// and bvh8-sah run the same kernel); the binary stack and `bvh4-hash` ran faster on the grid
    /// on 7 of the 8, and the packet kernel alike on both.
    /// Measured in `docs/notes/*-benchmarks-h100-suite.md`, "On an NVIDIA H100".
    pub fn for_method(self, method: Method) -> Dispatch {
        match self {
            Dispatch::ByMethod => match method.wide() {
                Some(m) if m.walk() == WideWalk::Stack => Dispatch::PERSISTENT,
                _ => Dispatch::Grid,
            },
            concrete => concrete,
        }
    }

    /// The name in reports and on the command line: `auto`, `grid`, or `persistent` (with
    /// `:<workgroups>` where that is not the default).
    pub fn name(&self) -> String {
        match *self {
            Dispatch::ByMethod => "auto".into(),
            Dispatch::Grid => "grid".into(),
            Dispatch::Persistent { workgroups: DEFAULT_PERSISTENT_WORKGROUPS } => "persistent".into(),
            Dispatch::Persistent { workgroups } => format!("persistent:{workgroups}"),
        }
    }

    /// Parses [`Dispatch::name`]'s forms; the error names what was expected.
    pub fn parse(s: &str) -> Result<Dispatch, Error> {
        let bad = || Error::InvalidParameter {
            name: "dispatch",
            why: "expected auto, grid, persistent or persistent:<workgroups> with at least one workgroup",
        };
        match s.split_once(':') {
            None if s == "auto" => Ok(Dispatch::ByMethod),
            None if s == "grid" => Ok(Dispatch::Grid),
            None if s == "persistent" => Ok(Dispatch::PERSISTENT),
            Some(("persistent", n)) => match n.parse::<u32>() {
                Ok(w) if w > 0 => Ok(Dispatch::Persistent { workgroups: w }),
                _ => Err(bad()),
            },
            _ => Err(bad()),
        }
    }
}

/// Workgroups of [`Dispatch::PERSISTENT`]: enough to keep a large GPU's cores busy (an H100 has
/// 132 SMs, each holding up to 64 warps), few enough that each fetches many batches.
pub const DEFAULT_PERSISTENT_WORKGROUPS: u32 = 4096;

/// The most rounds a persistent workgroup loops through (see [`Dispatch::Persistent`]).
pub const MAX_PERSISTENT_ROUNDS: usize = 4096;

/// The most rounds on a CPU adapter. Mesa's llvmpipe (lavapipe) runs workgroups one after another
/// and ends an invocation's loops once they have run 65,535 iterations in all, every loop of the
/// shader counting against the one limit: unbounded, the first workgroup took nearly every item
/// and stopped in the middle of one, leaving hits unwritten (seen on the conformance suite's
/// adversarial rays with kd-packet). Two rounds still run the fetch loop; a batch whose loops the
/// guard finds cut short is traced again with one item per SIMD group (shaders/loop_guard.wgsl).
pub const CPU_ADAPTER_ROUNDS: usize = 2;

/// The stream kernel's steps per round on a CPU adapter (shaders/wide_ray_stream.wgsl): a step's
/// loops run at most 32 rays x (a leaf of 8 triangles, or 8 children, and the loops over them),
/// about 800 iterations, so 48 steps stay well within lavapipe's 65,535 (see
/// [`CPU_ADAPTER_ROUNDS`]).
pub const CPU_ADAPTER_STREAM_STEPS: u32 = 48;

/// Default rays per batch: big enough to fill a large GPU many times over, small enough that a
/// trace of millions of rays is several batches, so that transfers overlap with kernels.
pub const DEFAULT_BATCH_RAYS: usize = 1 << 20;

/// Settings of a [`WgpuBackend`](crate::WgpuBackend); `GpuConfig::default()` is what
/// [`WgpuBackend::new`](crate::WgpuBackend::new) uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GpuConfig {
    /// Rays per batch, before the device's limits lower it.
    pub batch_rays: usize,
    /// Batches submitted before the first one's results are waited for (at least 1).
    pub in_flight: usize,
    /// How invocations get their rays.
    pub dispatch: Dispatch,
    /// Invocations per workgroup (a pipeline override; at most the device's limit).
    pub workgroup_size: u32,
}

impl Default for GpuConfig {
    fn default() -> Self {
        GpuConfig { batch_rays: DEFAULT_BATCH_RAYS, in_flight: 3, dispatch: Dispatch::ByMethod, workgroup_size: 64 }
    }
}

impl GpuConfig {
    /// Checks the settings against each other and the device's `limits`; the error names the
    /// setting and its bound.
    pub(crate) fn check(&self, limits: &wgpu::Limits) -> Result<(), Error> {
        let invalid = |name, why| Err(Error::InvalidParameter { name, why });
        if self.workgroup_size == 0 {
            return invalid("workgroup_size", "must be at least 1");
        }
        if self.batch_rays == 0 {
            return invalid("batch_rays", "a batch must hold at least one ray");
        }
        if self.in_flight == 0 {
            return invalid("in_flight", "at least one batch must be in flight");
        }
        if let Dispatch::Persistent { workgroups: 0 } = self.dispatch {
            return invalid("dispatch", "persistent threads need at least one workgroup");
        }
        let max_wg = limits.max_compute_workgroup_size_x.min(limits.max_compute_invocations_per_workgroup);
        if self.workgroup_size > max_wg {
            return Err(device_error(format!(
                "workgroup size {} is outside 1..={max_wg}, the adapter's limit",
                self.workgroup_size
            )));
        }
        Ok(())
    }

    /// The name in reports: the dispatch and the workgroup size, e.g. `grid/64`.
    pub fn label(&self) -> String {
        format!("{}/{}", self.dispatch.name(), self.workgroup_size)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dispatch_names_parse_back() {
        for d in [Dispatch::ByMethod, Dispatch::Grid, Dispatch::PERSISTENT, Dispatch::Persistent { workgroups: 7 }] {
            assert_eq!(Dispatch::parse(&d.name()).expect("parses"), d);
        }
        for bad in ["", "persistent:0", "persistent:x", "grid:4", "warp"] {
            assert!(Dispatch::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn by_method_is_persistent_for_the_wide_stack_methods_only() {
        use raytrail_core::method::WideMethod;
        for m in Method::ALL {
            let stack = matches!(
                m,
                Method::Wide(WideMethod::BVH4 | WideMethod::BVH8 | WideMethod::BVH4_NAIVE | WideMethod::BVH8_SAH)
            );
            let want = if stack { Dispatch::PERSISTENT } else { Dispatch::Grid };
            assert_eq!(Dispatch::ByMethod.for_method(m), want, "{m}");
            // A dispatch asked for by name stays what it is.
            assert_eq!(Dispatch::Grid.for_method(m), Dispatch::Grid);
            assert_eq!(Dispatch::PERSISTENT.for_method(m), Dispatch::PERSISTENT);
        }
    }

    #[test]
    fn settings_outside_the_limits_are_errors() {
        let limits = wgpu::Limits::default();
        assert!(GpuConfig::default().check(&limits).is_ok());
        let bad = [
            GpuConfig { workgroup_size: 0, ..GpuConfig::default() },
            GpuConfig { workgroup_size: 1 << 20, ..GpuConfig::default() },
            GpuConfig { batch_rays: 0, ..GpuConfig::default() },
            GpuConfig { in_flight: 0, ..GpuConfig::default() },
            GpuConfig { dispatch: Dispatch::Persistent { workgroups: 0 }, ..GpuConfig::default() },
        ];
        for c in bad {
            assert!(c.check(&limits).is_err(), "{c:?}");
        }
    }
}
