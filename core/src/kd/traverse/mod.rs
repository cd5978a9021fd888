//! kd-tree traversal state machines (Horn et al. 2007, Appendix A).
//!
//! One node per step, like the BVH2 methods; every method shares the tie rule of [`cross`] and the
//! early exit of [`kd_leaf`], so all of them visit the same leaves in the same order:
//! - [`KdStackState`]: the standard stack traversal (A.1);
//! - [`KdRestartState`]: kd-restart (A.2), push-down (A.3) and short-stack (A.4), which differ in
//!   whether the restart point moves down and how many entries the stack keeps;
//! - [`trace_kd_packet`]: the packetized short-stack (A.5), over packets grouped by [`packets`].

mod leaf;
mod packet;
pub use crate::traverse::packets;
mod restart;
mod run;
mod split;
mod stack;

pub use leaf::kd_leaf;
pub use packet::{trace_kd_packet, PACKET_WIDTH};
pub use restart::{KdRestartState, RestartPolicy, SHORT_STACK_MAX};
pub use run::{scene_interval, trace_kd_ray, KdRoot};
pub use split::{cross, Crossing};
pub use stack::KdStackState;
