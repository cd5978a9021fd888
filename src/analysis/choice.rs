//! Choosing a method for a kind of ray by timing the candidates on a sample of the rays.
//!
//! The decision is separate from the clock ([`SampleClock`]), so the rule can be tested with
//! made-up timings and the CPU backend's clock ([`super::sample::CpuClock`]) plugs in for real
//! runs.

use raytrail_core::method::{Bvh2Method, KdMethod, Method, StreamMethod, WideMethod};
use raytrail_core::Error;

/// The methods `auto` chooses among, one per family that was the fastest somewhere in
/// BENCHMARKS.md: the 8-wide tree (most secondary rays, every dragon ray), the kd stack traversal
/// (primary rays in architectural scenes), the BVH2 stack method (some coherent shadow rays) and
/// the ray-stream method (coherent primary rays inside rooms). The others each trail one of these
/// by more than they could gain (bvh4 trails bvh8, kd-short-stack and kd-packet trail or tie
/// kd-stack, the stackless BVH2 methods tie or trail stack on this CPU).
pub const CANDIDATES: [Method; 4] = [
    Method::Wide(WideMethod::Bvh8),
    Method::Kd(KdMethod::Stack),
    Method::Bvh2(Bvh2Method::Stack),
    Method::Stream(StreamMethod::Frustum8),
];

/// Timed rounds over the sample, the first over every candidate. The median of the rounds
/// decides.
pub const ROUNDS: usize = 3;

/// A candidate slower than this many times the fastest in the first round is not timed again:
/// noise on a shared machine moves single runs by tens of percent, not by half.
pub const PRUNE_FACTOR: f64 = 1.5;

/// Times one trace of the sample with a method.
pub trait SampleClock {
    /// Seconds one trace of the sample takes with `method`.
    fn seconds(&mut self, method: Method) -> Result<f64, Error>;
}

/// One candidate's timings on the sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Timed {
    /// The method.
    pub method: Method,
    /// Seconds of each round it took part in.
    pub seconds: Vec<f64>,
}

impl Timed {
    /// Median seconds over its rounds (the upper median of an even count, as a cautious value).
    pub fn median(&self) -> f64 {
        let mut s = self.seconds.clone();
        s.sort_by(f64::total_cmp);
        s.get(s.len() / 2).copied().unwrap_or(f64::INFINITY)
    }

    /// Whether it was dropped after the first round.
    pub fn pruned(&self) -> bool {
        self.seconds.len() < ROUNDS
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
}

impl Choice {
    /// The chosen method's median seconds on the sample.
    pub fn best_seconds(&self) -> f64 {
        self.timed.iter().find(|t| t.method == self.method).map_or(f64::INFINITY, Timed::median)
    }
}

/// Times every candidate once, drops those slower than [`PRUNE_FACTOR`] times the fastest, times
/// the rest for `rounds - 1` more rounds (round-robin, so a slow spell of the machine spreads over
/// all of them), and returns the one with the smallest median; ties go to the earlier candidate.
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
    let mut timed: Vec<Timed> = candidates.iter().map(|&method| Timed { method, seconds: Vec::new() }).collect();
    let mut cost = 0.0;
    for t in &mut timed {
        let s = clock.seconds(t.method)?;
        cost += s;
        t.seconds.push(sane(s));
    }
    let fastest = timed.iter().map(|t| t.seconds[0]).fold(f64::INFINITY, f64::min);
    let keep: Vec<bool> = timed.iter().map(|t| t.seconds[0] <= PRUNE_FACTOR * fastest).collect();
    for _ in 1..rounds {
        for (t, _) in timed.iter_mut().zip(&keep).filter(|(_, &k)| k) {
            let s = clock.seconds(t.method)?;
            cost += s;
            t.seconds.push(sane(s));
        }
    }
    let mut best = 0;
    for (i, t) in timed.iter().enumerate() {
        // Only the candidates that ran every round compete on their medians.
        if keep[i] && (!keep[best] || t.median() < timed[best].median()) {
            best = i;
        }
    }
    Ok(Choice { method: timed[best].method, timed, cost_seconds: cost })
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
    use std::collections::HashMap;

    /// A clock replaying given times per method, round by round.
    struct Replay {
        times: HashMap<Method, Vec<f64>>,
        calls: Vec<Method>,
    }

    impl Replay {
        fn new(times: &[(Method, &[f64])]) -> Self {
            Replay { times: times.iter().map(|(m, t)| (*m, t.to_vec())).collect(), calls: Vec::new() }
        }
    }

    impl SampleClock for Replay {
        fn seconds(&mut self, method: Method) -> Result<f64, Error> {
            let round = self.calls.iter().filter(|&&m| m == method).count();
            self.calls.push(method);
            Ok(self.times[&method][round])
        }
    }

    const BVH8: Method = CANDIDATES[0];
    const KD: Method = CANDIDATES[1];
    const STACK: Method = CANDIDATES[2];
    const STREAM: Method = CANDIDATES[3];

    #[test]
    fn the_smallest_median_wins_not_the_smallest_single_run() {
        // kd-stack has the best single run (a lucky one) but bvh8 the better median.
        let mut clock = Replay::new(&[(BVH8, &[1.0, 1.0, 1.1]), (KD, &[1.2, 0.5, 1.3]), (STACK, &[1.4, 1.4, 1.4])]);
        let c = choose(&[BVH8, KD, STACK], 3, &mut clock).unwrap();
        assert_eq!(c.method, BVH8);
        assert_eq!(c.timed[1].median(), 1.2);
        assert!((c.cost_seconds - 10.3).abs() < 1e-9, "{}", c.cost_seconds);
    }

    #[test]
    fn slow_candidates_are_timed_once() {
        let mut clock = Replay::new(&[(BVH8, &[1.0, 1.0, 1.0]), (KD, &[0.9, 0.9, 0.9]), (STREAM, &[1.36, 0.1, 0.1])]);
        let c = choose(&[BVH8, KD, STREAM], 3, &mut clock).unwrap();
        assert_eq!(c.method, KD);
        // Round-robin: both survivors alternate after the first round; the stream method, over
        // 1.5 times the fastest, is not run again (its fast later runs are never seen).
        assert_eq!(clock.calls, [BVH8, KD, STREAM, BVH8, KD, BVH8, KD]);
        assert!(c.timed[2].pruned() && !c.timed[0].pruned());
    }

    #[test]
    fn a_candidate_within_the_prune_factor_stays_in() {
        let mut clock = Replay::new(&[(BVH8, &[1.0, 1.0, 1.0]), (STREAM, &[1.49, 0.5, 0.5])]);
        let c = choose(&[BVH8, STREAM], 3, &mut clock).unwrap();
        assert_eq!(c.method, STREAM);
    }

    #[test]
    fn ties_go_to_the_earlier_candidate() {
        let mut clock = Replay::new(&[(STACK, &[1.0, 1.0, 1.0]), (BVH8, &[1.0, 1.0, 1.0])]);
        assert_eq!(choose(&[STACK, BVH8], 3, &mut clock).unwrap().method, STACK);
    }

    #[test]
    fn broken_clock_readings_never_win() {
        let mut clock = Replay::new(&[(STACK, &[f64::NAN, 0.0, 0.0]), (BVH8, &[2.0, 2.0, 2.0])]);
        assert_eq!(choose(&[STACK, BVH8], 3, &mut clock).unwrap().method, BVH8);
        let mut clock = Replay::new(&[(STACK, &[-1.0, -1.0, -1.0])]);
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
        fn seconds(&mut self, method: Method) -> Result<f64, Error> {
            Err(Error::NotPrepared { method: method.name(), missing: "everything" })
        }
    }

    #[test]
    fn clock_errors_pass_through() {
        assert!(matches!(choose(&CANDIDATES, 3, &mut Failing), Err(Error::NotPrepared { .. })));
    }
}
