//! Choosing a method for a kind of ray by timing the candidates on a sample of the rays.
//!
//! The decision is separate from the clock ([`SampleClock`]), so the rule can be tested with
//! made-up timings and the CPU backend's clock ([`super::sample::CpuClock`]) plugs in for real
//! runs.

use raytrail_core::method::{KdMethod, Method, WideMethod};
use raytrail_core::Error;

/// The methods `auto` chooses among, one per family that was the fastest somewhere in the notes
/// (`docs/notes/`): the 8-wide tree of least node area walked by single rays (the cheapest to get
/// wrong, so first), by packets (camera rays, shadow rays toward one light) and by ray lists
/// (large batches of incoherent rays, closest or any hit); the pull-up tree by packets and by
/// ray lists (shadow rays through deep geometry); and the kd stack traversal (ambient occlusion
/// from outside architectural scenes). The others each trail one of these by more than they
/// could gain (bvh4 trails bvh8, kd-short-stack and kd-packet trail or tie kd-stack, the BVH2
/// methods and the ray-stream method trail the wide walks on this CPU; on trees with spatial
/// splits the single-ray walk of the least-area tree leads the pull-up tree's,
/// `docs/notes/*-spatial-splits.md`).
pub const CANDIDATES: [Method; 6] = [
    Method::Wide(WideMethod::BVH8_SAH),
    Method::Wide(WideMethod::BVH8_SAH_PACKET),
    Method::Wide(WideMethod::BVH8_SAH_LISTS),
    Method::Wide(WideMethod::BVH8_PACKET),
    Method::Wide(WideMethod::BVH8_LISTS),
    Method::Kd(KdMethod::Stack),
];

/// Timed rounds over the whole sample among the candidates that survive the first look; the
/// median of the rounds decides.
pub const ROUNDS: usize = 3;

/// A candidate slower than this many times the fastest at the first look is not timed again. The
/// first look traces a few hundred rays, and on so few the methods' ratios stray from the batch's
/// by up to about 1.9 times (kd-stack looked 1.54 times slower than bvh8 on camera rays into
/// Sponza, and is 1.8 times faster over the batch), so only the grossly slow go here: the stream
/// method on incoherent rays, 5 to 15 times slower.
pub const PRUNE_FACTOR: f64 = 2.5;

/// A candidate slower than this many times the fastest in the first round on the whole sample is
/// not timed again: the whole sample ranks the methods as the batch does, and noise on a shared
/// machine moves single runs by tens of percent, not by half.
pub const ROUND_PRUNE_FACTOR: f64 = 1.5;

/// A later candidate must be faster than an earlier one by more than this fraction of its time to
/// be chosen over it. A sample is a small working set, which flatters the methods with larger
/// structures: on camera rays into the kitchen, samples had kd-stack (8 references per triangle)
/// up to 7% ahead of bvh8, and the whole batch 12-16% behind it (it was 5% until that sample
/// chose kd-stack in two of three runs). A margin of 10% keeps an earlier candidate unless the
/// sample says it loses by more than the tolerance `auto` is held to. The candidates come in the
/// order that is cheapest to get wrong, bvh8 first.
pub const EARLIER_MARGIN: f64 = 0.10;

/// How much of the sample a trace covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Portion {
    /// The first look: every candidate once on part of the sample (a slow candidate, such as the
    /// stream method on incoherent rays, then costs a part of a sample, not a whole one).
    Part,
    /// The timed rounds: the whole sample.
    Whole,
}

/// Times one trace of the sample with a method.
pub trait SampleClock {
    /// Seconds one trace of `portion` of the sample takes with `method`.
    fn seconds(&mut self, method: Method, portion: Portion) -> Result<f64, Error>;
}

/// One candidate's timings on the sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Timed {
    /// The method.
    pub method: Method,
    /// Seconds of its first look, on part of the sample.
    pub first: f64,
    /// Seconds of each timed round on the whole sample (none when it was dropped at the first
    /// look, or was the only one left).
    pub seconds: Vec<f64>,
    /// Whether it was dropped before the last round: at the first look, or after the first round.
    pub dropped: bool,
}

impl Timed {
    /// Median seconds over its rounds on the whole sample (the upper median of an even count, as
    /// a cautious value); infinite without rounds.
    pub fn median(&self) -> f64 {
        let mut s = self.seconds.clone();
        s.sort_by(f64::total_cmp);
        s.get(s.len() / 2).copied().unwrap_or(f64::INFINITY)
    }

    /// Whether it was dropped at the first look (it has no rounds).
    pub fn pruned(&self) -> bool {
        self.dropped && self.seconds.is_empty()
    }
}

/// What was chosen, and on what evidence.
#[derive(Clone, Debug, PartialEq)]
pub struct Choice {
    /// The fastest candidate by median.
    pub method: Method,
    /// Every candidate's timings, in candidate order.
    pub timed: Vec<Timed>,
    /// Total seconds spent timing (the cost of choosing, beyond preparing the candidates).
    pub cost_seconds: f64,
    /// The verdict on the list walk of the sample winner's tree, where one was reached
    /// ([`super::streams::judge`]); `method` is the list walk where it won.
    pub lists: Option<super::streams::ListsVerdict>,
}

impl Choice {
    /// One line for reports: each candidate's first look on part of the sample (µs), and the
    /// median over the rounds where it went on to them.
    pub fn summary(&self) -> String {
        let each: Vec<String> = self
            .timed
            .iter()
            .map(|t| {
                let first = format!("{} {:.0}", t.method.name(), 1e6 * t.first);
                match (t.dropped, t.seconds.is_empty()) {
                    (true, true) => format!("{first} dropped"),
                    (true, false) => format!("{first}, round {:.0} dropped", 1e6 * t.median()),
                    (false, true) => first,
                    (false, false) => format!("{first}, rounds {:.0}", 1e6 * t.median()),
                }
            })
            .collect();
        let check = self.lists.as_ref().map_or(String::new(), |v| format!("; {}", v.summary()));
        format!("µs (first look on part of the sample, then median of the rounds): {}{check}", each.join("; "))
    }

    /// The chosen method's median seconds on the sample (infinite for a list walk, which is not
    /// timed on it).
    pub fn best_seconds(&self) -> f64 {
        self.timed.iter().find(|t| t.method == self.method).map_or(f64::INFINITY, Timed::median)
    }
}

/// Times every candidate once on part of the sample, drops those slower than [`PRUNE_FACTOR`]
/// times the fastest, and, if more than one is left, times those for `rounds` rounds on the whole
/// sample (round-robin, so a slow spell of the machine spreads over all of them; after the first
/// round, those slower than [`ROUND_PRUNE_FACTOR`] times its fastest are dropped) and returns the
/// one with the smallest median, where a later candidate must beat an earlier one by more than
/// [`EARLIER_MARGIN`]. A lone survivor is chosen without more timing.
///
/// Fails with [`Error::InvalidParameter`] for no candidates or no rounds, and passes on the
/// clock's errors.
pub fn choose(candidates: &[Method], rounds: usize, clock: &mut dyn SampleClock) -> Result<Choice, Error> {
    if candidates.is_empty() {
        return Err(Error::InvalidParameter { name: "candidates", why: "at least one method to choose from" });
    }
    if rounds == 0 {
        return Err(Error::InvalidParameter { name: "rounds", why: "at least one timed round" });
    }
    let mut cost = 0.0;
    let mut timed = Vec::with_capacity(candidates.len());
    for &method in candidates {
        let s = clock.seconds(method, Portion::Part)?;
        cost += s;
        timed.push(Timed { method, first: sane(s), seconds: Vec::new(), dropped: false });
    }
    let mut left: Vec<usize> = (0..timed.len()).collect();
    drop_slower(&mut timed, &mut left, PRUNE_FACTOR, |t| t.first);
    if left.len() > 1 {
        for round in 0..rounds {
            for &i in &left {
                let s = clock.seconds(timed[i].method, Portion::Whole)?;
                cost += s;
                timed[i].seconds.push(sane(s));
            }
            if round == 0 {
                drop_slower(&mut timed, &mut left, ROUND_PRUNE_FACTOR, |t| t.seconds[0]);
                if left.len() == 1 {
                    break;
                }
            }
        }
    }
    // The first survivor, unless a later one's median is smaller by more than the margin.
    let mut best = left[0];
    for &i in &left[1..] {
        if timed[i].median() < (1.0 - EARLIER_MARGIN) * timed[best].median() {
            best = i;
        }
    }
    Ok(Choice { method: timed[best].method, timed, cost_seconds: cost, lists: None })
}

/// Marks dropped, and removes from `left`, the candidates whose `time` exceeds `factor` times the
/// fastest of `left`.
fn drop_slower(timed: &mut [Timed], left: &mut Vec<usize>, factor: f64, time: impl Fn(&Timed) -> f64) {
    let fastest = left.iter().map(|&i| time(&timed[i])).fold(f64::INFINITY, f64::min);
    for &i in left.iter() {
        timed[i].dropped = time(&timed[i]) > factor * fastest;
    }
    left.retain(|&i| !timed[i].dropped);
}

/// A clock reading that cannot win: NaN and negative times become infinite.
fn sane(s: f64) -> f64 {
    if s.is_nan() || s < 0.0 {
        f64::INFINITY
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail_core::method::{Bvh2Method, StreamMethod};
    use std::collections::HashMap;

    /// A clock replaying given times per method: the first look's, then the rounds'.
    struct Replay {
        times: HashMap<Method, (f64, Vec<f64>)>,
        calls: Vec<(Method, Portion)>,
    }

    impl Replay {
        fn new(times: &[(Method, f64, &[f64])]) -> Self {
            Replay { times: times.iter().map(|(m, f, t)| (*m, (*f, t.to_vec()))).collect(), calls: Vec::new() }
        }
    }

    impl SampleClock for Replay {
        fn seconds(&mut self, method: Method, portion: Portion) -> Result<f64, Error> {
            let round = self.calls.iter().filter(|&&c| c == (method, Portion::Whole)).count();
            self.calls.push((method, portion));
            let (first, rounds) = &self.times[&method];
            Ok(match portion {
                Portion::Part => *first,
                Portion::Whole => rounds[round],
            })
        }
    }

    const BVH8: Method = Method::Wide(WideMethod::BVH8);
    const KD: Method = Method::Kd(KdMethod::Stack);
    const STACK: Method = Method::Bvh2(Bvh2Method::Stack);
    const STREAM: Method = Method::Stream(StreamMethod::Frustum8);

    #[test]
    fn the_smallest_median_wins_not_the_smallest_single_run() {
        // kd-stack has the best single run (a lucky one) but bvh8 the better median.
        let mut clock =
            Replay::new(&[(BVH8, 0.3, &[1.0, 1.0, 1.1]), (KD, 0.3, &[1.2, 0.5, 1.3]), (STACK, 0.4, &[1.4, 1.4, 1.4])]);
        let c = choose(&[BVH8, KD, STACK], 3, &mut clock).unwrap();
        assert_eq!(c.method, BVH8);
        assert_eq!(c.timed[1].median(), 1.2);
        assert!((c.cost_seconds - (1.0 + 10.3)).abs() < 1e-9, "{}", c.cost_seconds);
    }

    #[test]
    fn slow_candidates_are_looked_at_once_on_part_of_the_sample() {
        let mut clock =
            Replay::new(&[(BVH8, 1.0, &[1.0, 1.0, 1.0]), (KD, 0.9, &[0.8, 0.8, 0.8]), (STREAM, 2.3, &[0.1, 0.1, 0.1])]);
        let c = choose(&[BVH8, KD, STREAM], 3, &mut clock).unwrap();
        assert_eq!(c.method, KD);
        // The first look covers part of the sample; then the survivors alternate over the
        // whole; the stream method, over 2.5 times the fastest, is not run again (its fast later
        // runs are never seen).
        use Portion::{Part, Whole};
        assert_eq!(
            clock.calls,
            [
                (BVH8, Part),
                (KD, Part),
                (STREAM, Part),
                (BVH8, Whole),
                (KD, Whole),
                (BVH8, Whole),
                (KD, Whole),
                (BVH8, Whole),
                (KD, Whole)
            ]
        );
        assert!(c.timed[2].pruned() && !c.timed[0].pruned());
    }

    #[test]
    fn a_lone_survivor_is_chosen_without_more_timing() {
        let mut clock = Replay::new(&[(BVH8, 1.0, &[]), (KD, 2.6, &[]), (STACK, 3.0, &[])]);
        let c = choose(&[KD, STACK, BVH8], 3, &mut clock).unwrap();
        assert_eq!(c.method, BVH8);
        assert_eq!(clock.calls.len(), 3);
        assert!((c.cost_seconds - 6.6).abs() < 1e-9);
    }

    #[test]
    fn a_candidate_within_the_prune_factor_stays_in() {
        let mut clock = Replay::new(&[(BVH8, 1.0, &[1.0, 1.0, 1.0]), (STREAM, 2.49, &[0.5, 0.5, 0.5])]);
        let c = choose(&[BVH8, STREAM], 3, &mut clock).unwrap();
        assert_eq!(c.method, STREAM);
    }

    #[test]
    fn a_candidate_far_behind_in_the_first_round_is_not_timed_again() {
        // kd-stack looked fastest on the small part; the whole sample shows it 1.6 times slower.
        let mut clock =
            Replay::new(&[(BVH8, 1.0, &[1.0, 1.0, 1.0]), (KD, 0.6, &[1.6, 0.1, 0.1]), (STACK, 1.2, &[1.2, 1.1, 1.3])]);
        let c = choose(&[BVH8, KD, STACK], 3, &mut clock).unwrap();
        assert_eq!(c.method, BVH8);
        assert_eq!(clock.calls.iter().filter(|&&(m, p)| m == KD && p == Portion::Whole).count(), 1);
        assert!(c.timed[1].dropped && !c.timed[1].pruned(), "dropped after a round, not at the first look");
        assert_eq!(c.timed[2].seconds.len(), 3);
        // A lone survivor of the first round is not timed again.
        let mut clock = Replay::new(&[(BVH8, 1.0, &[1.0, 9.0, 9.0]), (KD, 1.0, &[2.0, 0.1, 0.1])]);
        assert_eq!(choose(&[BVH8, KD], 3, &mut clock).unwrap().method, BVH8);
        assert_eq!(clock.calls.len(), 4);
    }

    #[test]
    fn ties_go_to_the_earlier_candidate() {
        let mut clock = Replay::new(&[(STACK, 1.0, &[1.0, 1.0, 1.0]), (BVH8, 1.0, &[1.0, 1.0, 1.0])]);
        assert_eq!(choose(&[STACK, BVH8], 3, &mut clock).unwrap().method, STACK);
        // Within the margin is a tie too; beyond it the later one wins.
        let mut clock = Replay::new(&[(BVH8, 1.0, &[1.0, 1.0, 1.0]), (KD, 1.0, &[0.91, 0.91, 0.91])]);
        assert_eq!(choose(&[BVH8, KD], 3, &mut clock).unwrap().method, BVH8);
        let mut clock = Replay::new(&[(BVH8, 1.0, &[1.0, 1.0, 1.0]), (KD, 1.0, &[0.89, 0.89, 0.89])]);
        assert_eq!(choose(&[BVH8, KD], 3, &mut clock).unwrap().method, KD);
    }

    #[test]
    fn broken_clock_readings_never_win() {
        let mut clock = Replay::new(&[(STACK, f64::NAN, &[0.0; 3]), (BVH8, 2.0, &[2.0; 3])]);
        assert_eq!(choose(&[STACK, BVH8], 3, &mut clock).unwrap().method, BVH8);
        let mut clock = Replay::new(&[(STACK, 1.0, &[f64::NAN; 3]), (BVH8, 1.0, &[2.0; 3])]);
        assert_eq!(choose(&[STACK, BVH8], 3, &mut clock).unwrap().method, BVH8);
        let mut clock = Replay::new(&[(STACK, -1.0, &[])]);
        let c = choose(&[STACK], 3, &mut clock).unwrap();
        assert_eq!(c.method, STACK, "the only candidate is chosen whatever its time");
    }

    #[test]
    fn bad_arguments_are_errors() {
        let mut clock = Replay::new(&[]);
        assert!(matches!(choose(&[], 3, &mut clock), Err(Error::InvalidParameter { name: "candidates", .. })));
        assert!(matches!(choose(&[BVH8], 0, &mut clock), Err(Error::InvalidParameter { name: "rounds", .. })));
    }

    /// A clock that fails: its error comes back unchanged.
    struct Failing;
    impl SampleClock for Failing {
        fn seconds(&mut self, method: Method, _: Portion) -> Result<f64, Error> {
            Err(Error::NotPrepared { method: method.name(), missing: "everything" })
        }
    }

    #[test]
    fn clock_errors_pass_through() {
        assert!(matches!(choose(&CANDIDATES, 3, &mut Failing), Err(Error::NotPrepared { .. })));
    }
}
