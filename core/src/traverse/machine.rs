//! The one interface over every per-ray traversal, and its one budgeted driver.
//!
//! Each method is a small per-ray state (the registers its paper names) whose [`Machine::step`]
//! makes one transition: it visits one node or leaf and says what is left ([`Step`]). Everything
//! that traces a single ray drives a [`Machine`]: the CPU and serial backends and the embedded
//! example through [`Machine::run`], the lockstep simulator one [`Machine::step`] at a time
//! (docs/ARCHITECTURE.md, "Traversal: a state machine plus an observer").

use super::{QueryState, Step};
use crate::observe::Observer;

/// A per-ray traversal state over memory `Mem` with per-ray constants `Ctx`.
pub trait Machine<Mem: ?Sized, Ctx> {
    /// One transition; see [`Step`].
    fn step<O: Observer>(&mut self, mem: &Mem, ctx: &Ctx, q: &mut QueryState, obs: &mut O) -> Step;

    /// Steps until the ray is done, or for at most `max_steps` further steps after the first (a
    /// budget that never binds on an intact structure and ends every walk on a damaged one).
    ///
    /// A state may override this with a loop that keeps its registers in locals, provided it
    /// makes `step`'s transitions in `step`'s order: the same answer and the same events
    /// (`core/tests/run_loops.rs` holds each override to that).
    #[inline(always)]
    fn run<O: Observer>(&mut self, mem: &Mem, ctx: &Ctx, q: &mut QueryState, obs: &mut O, max_steps: u32) {
        drive(self, mem, ctx, q, obs, max_steps);
    }
}

/// Steps `state` until it is done, or for at most `max_steps` further steps after the first: the
/// default [`Machine::run`], and the reference that every override is tested against.
#[inline(always)]
pub fn drive<Mem: ?Sized, Ctx, S: Machine<Mem, Ctx> + ?Sized, O: Observer>(
    state: &mut S,
    mem: &Mem,
    ctx: &Ctx,
    q: &mut QueryState,
    obs: &mut O,
    max_steps: u32,
) {
    let mut budget = max_steps;
    while state.step(mem, ctx, q, obs) != Step::Done && budget > 0 {
        budget -= 1;
    }
}
