//! What the lockstep driver needs from a structure: how a lane begins, how it steps, and what a
//! step did beyond the core's observer events.

use crate::memory::Traffic;
use crate::sim::LaneObserver;
use raytrail_core::traverse::{QueryState, Step};
use raytrail_core::Ray;

/// What one lane's step did that the core's events do not say directly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Outcome {
    /// The step's outcome.
    pub step: Step,
    /// The lane paused and resumed during the step (hash-resume only).
    pub resumed: bool,
    /// Children postponed (entered later, or left to a restart).
    pub postponed: u32,
    /// Entries written to a stack.
    pub pushed: u32,
    /// Entries pushed off the bottom of a full short stack.
    pub dropped: u32,
    /// The step's chain of dependent memory reads.
    pub rounds: u32,
}

/// One structure's lanes over one method: the state machines of the core, stepped one
/// transition at a time, reading through a counting memory.
pub(crate) trait Stepper {
    /// A lane's per-ray state: the core's state machine and the ray's constants.
    type Lane;
    /// The lane for `ray`, or `None` where the CPU backend's loop would not step at all.
    fn begin(&self, ray: &Ray) -> Option<Self::Lane>;
    /// One transition of `lane`.
    fn step(&self, lane: &mut Self::Lane, q: &mut QueryState, obs: &mut LaneObserver) -> Outcome;
    /// Steps after which a lane stops (the CPU backend's budget).
    fn max_steps(&self) -> u32;
    /// Bytes of one stack entry; 0 for a method without a stack.
    fn stack_entry_bytes(&self) -> u64;
    /// Ends a warp-step: the distinct cache lines it touched.
    fn end_cycle(&self) -> u64;
    /// What has been read so far.
    fn traffic(&self) -> Traffic;
}
