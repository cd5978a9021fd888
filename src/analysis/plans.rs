//! `auto`'s choices kept per kind of batch, so that a caller's repeated calls (a camera's rays,
//! then each bounce, frame after frame) pay for choosing now and then rather than on every call.
//! Choosing times candidates on a sample of the batch and costs 15-70% of one trace of a batch of
//! 2^16-2^17 rays (`docs/notes/*-walk-experiments-and-auto-lists.md`, "Choices kept").

use raytrail_core::method::Query;
use raytrail_core::trace_order::{looks_coherent, origins_look_scattered};
use raytrail_core::Ray;

/// Calls a kept choice serves before its kind of batch is chosen for again, so that a choice
/// made on an odd batch does not stay, and choosing costs at most a sixteenth of what it would on
/// every call.
pub const REUSES: u32 = 15;

/// What a choice is kept under: what `auto`'s rules read of a batch. The query; the batch's size
/// to a power of two (the rules that look at size, sorting and the list walks' check and rule,
/// change at powers of two of rays a thread); whether neighbouring rays point alike and whether
/// they start far apart (the order tests of
/// [`TraceOrder::for_batch`](raytrail_core::trace_order::TraceOrder::for_batch)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BatchKind {
    query: Query,
    size_log2: u32,
    coherent: bool,
    scattered: bool,
}

impl BatchKind {
    /// The kind of `rays` answering `query` (32 pairs of neighbours read, whatever the batch's
    /// size).
    pub fn of(rays: &[Ray], query: Query) -> BatchKind {
        BatchKind {
            query,
            size_log2: rays.len().max(1).ilog2(),
            coherent: looks_coherent(rays),
            scattered: origins_look_scattered(rays),
        }
    }
}

/// Choices (`P`: a method and an order) by kind of batch, each with the calls it has served.
#[derive(Clone, Debug)]
pub struct Plans<P> {
    kept: Vec<(BatchKind, P, u32)>,
}

impl<P> Default for Plans<P> {
    fn default() -> Self {
        Plans { kept: Vec::new() }
    }
}

impl<P: Copy> Plans<P> {
    /// The choice kept for `kind`, counted as one more call served; `None` where there is none,
    /// or where it has served [`REUSES`] calls (it is then dropped, to be chosen again).
    pub fn reuse(&mut self, kind: BatchKind) -> Option<P> {
        let at = self.kept.iter().position(|(k, _, _)| *k == kind)?;
        let (_, plan, served) = &mut self.kept[at];
        if *served >= REUSES {
            self.kept.swap_remove(at);
            return None;
        }
        *served += 1;
        Some(*plan)
    }

    /// Keeps `plan` for `kind`, in place of any choice kept for it.
    pub fn keep(&mut self, kind: BatchKind, plan: P) {
        self.kept.retain(|(k, _, _)| *k != kind);
        self.kept.push((kind, plan, 0));
    }

    /// Forgets every choice (the scene changed under them).
    pub fn clear(&mut self) {
        self.kept.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail_core::glam::Vec3;

    fn rays(n: usize, coherent: bool) -> Vec<Ray> {
        (0..n)
            .map(|i| {
                let d = if coherent { Vec3::Z } else { [Vec3::X, Vec3::Y, -Vec3::X, -Vec3::Y][i % 4] };
                Ray::new(Vec3::new(i as f32, 0.0, 0.0), d, 0.0, f32::INFINITY)
            })
            .collect()
    }

    #[test]
    fn a_choice_serves_its_kind_a_number_of_times_then_is_made_again() {
        let kind = BatchKind::of(&rays(1000, true), Query::Closest);
        let mut plans = Plans::default();
        assert_eq!(plans.reuse(kind), None, "nothing chosen yet");
        plans.keep(kind, 'a');
        for _ in 0..REUSES {
            assert_eq!(plans.reuse(kind), Some('a'));
        }
        assert_eq!(plans.reuse(kind), None, "served its calls: chosen again");
        plans.keep(kind, 'b');
        assert_eq!(plans.reuse(kind), Some('b'));
        plans.clear();
        assert_eq!(plans.reuse(kind), None);
    }

    #[test]
    fn kinds_differ_by_query_size_and_order() {
        let base = BatchKind::of(&rays(1000, true), Query::Closest);
        assert_eq!(BatchKind::of(&rays(1010, true), Query::Closest), base, "the same power of two");
        assert_ne!(BatchKind::of(&rays(1000, true), Query::Any), base);
        assert_ne!(BatchKind::of(&rays(2000, true), Query::Closest), base);
        assert_ne!(BatchKind::of(&rays(1000, false), Query::Closest), base);
        let mut plans = Plans::default();
        plans.keep(base, 1);
        assert_eq!(plans.reuse(BatchKind::of(&rays(1000, true), Query::Any)), None);
        assert_eq!(plans.reuse(BatchKind::of(&[], Query::Closest)), None, "an empty batch has a kind too");
    }
}
