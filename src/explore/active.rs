//! Active touch (beyond the paper): the planner's hook for choosing where to touch next by what a
//! touch there is expected to teach, and the rule that ends exploration once the recogniser is sure.
//!
//! The paper closes with this as future work: "integrating our simulator into a planning system
//! which could optimize exploration [...] such as expected information gain" (Sec. VI), and chose
//! Eq. 4 because it "is more easily adaptable to integration with a guided search framework for
//! evaluating the potential information content of future measurements" (Sec. IV-A).
//!
//! Exploration knows nothing of descriptors or trained models (they come later in the data flow),
//! so the planner asks a [`TouchScorer`] to score its candidate targets; the recogniser implements
//! it (`active_touch`). With the strategy [`Strategy::Active`](crate::dataset::Strategy) the
//! planner draws [`ActiveGuidance::candidates`] targets per iteration exactly as its local/global
//! rule would (each local with probability L once a reading exists, else global), asks the scorer,
//! and expands toward the best one (the first of equal scores, so the choice is deterministic).
//! The planner is still told nothing of the object's identity, pose or shape: the scorer sees only
//! the readings it was given and their pad locations.
//!
//! A score is what a touch would teach *if* the iteration touches; most do not (a global target
//! lies in empty space more often than not: 2% of blind global iterations and 23% of local ones
//! end in a converged reading on the 3D set). Ranked by the score alone, the active strategy chose
//! unexplored empty space, which scores the mutual information, over the surface it had read:
//! 99% global iterations, about 1,700 iterations per reading (docs/measurements.md, "Active touch
//! that touches"). The planner therefore expands toward the candidate of the largest *expected
//! gain of the iteration*, `score(x) P(reading | x)`, with `P` estimated by [`TouchOdds`] from its
//! own earlier iterations; still nothing of the object.

use std::num::NonZeroUsize;

use glam::DVec3;

use crate::dataset::Strategy;
use crate::explore::cells::PointCells;
use crate::valid::checked_f64;

/// Scores candidate touch targets by what a touch there is expected to tell about the object's
/// identity, given the readings it has been shown so far.
pub trait TouchScorer {
    /// One score per target of `candidates_m` (world frame, metres), in order; larger is better.
    fn score(&self, candidates_m: &[DVec3]) -> Vec<f64>;
}

/// How the planner's active strategy uses a scorer.
#[derive(Clone, Copy)]
pub struct ActiveGuidance<'a> {
    pub scorer: &'a dyn TouchScorer,
    /// Candidate targets drawn and scored per iteration (at least 1; 1 is the plain planner).
    pub candidates: usize,
}

/// Candidates per iteration by default: enough for local and global proposals to both be present
/// at L = 0.5 (the chance that 12 draws are all of one kind is 2^-11), few enough that scoring
/// stays a small share of an iteration.
pub const DEFAULT_CANDIDATES: usize = 12;

checked_f64! {
    /// A probability in (0, 1]: the confidence at which exploration stops.
    pub struct Probability(p) where p > 0.0 && p <= 1.0;
    /// A value that is not a [`Probability`].
    pub enum ProbabilityError {
        OutOfRange = "{0} is not a probability in (0, 1]",
        NotANumber = "'{0}' is not a number",
    }
}

/// The confidence stop (beyond the paper): exploration ends once one object has been the
/// posterior's guess, with probability at least `threshold`, after each of the last
/// `held_readings` touches, or when the touch budget is spent.
///
/// Why more than one touch: the posterior is calibrated over every touch of an exploration
/// (`recognize::calibration`), but the first touch at which it crosses a threshold is selected for
/// being high, so a stop there was right less often than the threshold promises. Measured on the
/// `active` experiment's 648 runs at scale 1.0 (three seeds, docs/measurements.md), the stop at
/// 0.95 on the first such touch was right 94.1-98.7% of the time per curve, and 95.1-98.7% when
/// the guess had to hold over two touches, for 0.2 to 2.5 more touches on average.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConfidenceStop {
    threshold: Probability,
    held_readings: NonZeroUsize,
}

impl ConfidenceStop {
    /// Touches the guess must hold over unless told otherwise.
    pub const DEFAULT_HELD_READINGS: NonZeroUsize = NonZeroUsize::new(2).expect("2 is not 0");

    /// The stop at `threshold`, held over [`Self::DEFAULT_HELD_READINGS`] touches.
    pub fn new(threshold: Probability) -> Self {
        Self {
            threshold,
            held_readings: Self::DEFAULT_HELD_READINGS,
        }
    }

    /// The same stop held over `held_readings` touches (1: the first touch that reaches the
    /// threshold).
    pub fn held_over(self, held_readings: NonZeroUsize) -> Self {
        Self {
            held_readings,
            ..self
        }
    }

    pub fn threshold(&self) -> Probability {
        self.threshold
    }

    pub fn held_readings(&self) -> NonZeroUsize {
        self.held_readings
    }

    /// Whether the stop fires after the last touch of `trace`: each touch's guess (an object index)
    /// and the probability the posterior gives it, in order.
    pub fn fires(&self, trace: &[(usize, f64)]) -> bool {
        let held = self.held_readings.get();
        let Some(recent) = trace.len().checked_sub(held).map(|start| &trace[start..]) else {
            return false;
        };
        let guess = recent[recent.len() - 1].0;
        recent
            .iter()
            .all(|&(g, p)| g == guess && p >= self.threshold.get())
    }

    /// The touches used (1-based) given each touch's guess and its probability, or `None` when the
    /// stop never fires within `budget` touches (the budget is then spent).
    pub fn touches_used(&self, trace: &[(usize, f64)], budget: usize) -> Option<usize> {
        (1..=trace.len().min(budget)).find(|&k| self.fires(&trace[..k]))
    }
}

/// Pseudo-iterations of the strategy's overall rate that a neighbourhood's own record is weighed
/// against in [`TouchOdds::chance`]: two, so a neighbourhood's first failure halves neither its
/// chance nor a first success makes it certain.
pub const ODDS_PRIOR_ITERATIONS: f64 = 2.0;

/// Where the planner's iterations have found the object: every guided iteration's target, the kind
/// of move that carried the pad there and whether it ended in a converged reading. Only the
/// planner's own outcomes, never the object's pose or shape.
///
/// The targets are binned into cubes per kind, so that [`chance`](Self::chance), asked for every
/// candidate of every iteration, looks at the targets near the candidate rather than at all of
/// them (a scan of every target was half of an `active` experiment's time on the perturbed
/// object, whose explorations run to thousands of iterations).
#[derive(Debug, Clone)]
pub struct TouchOdds {
    cell_m: f64,
    kinds: Vec<KindOdds>,
}

/// The recorded iterations of one kind of move.
#[derive(Debug, Clone)]
struct KindOdds {
    strategy: Strategy,
    tried: usize,
    touched: usize,
    /// Each iteration's target and whether it touched.
    targets: PointCells<(DVec3, bool)>,
}

impl Default for TouchOdds {
    /// For chances asked within the planner's default local radius.
    fn default() -> Self {
        Self::new(crate::explore::PlannerConfig::default().local_radius_m)
    }
}

impl TouchOdds {
    /// No iteration yet, for chances asked within `radius_m` (any radius is answered exactly;
    /// this one fastest): the targets are binned in cubes a little wider than it, so that a query
    /// looks at the 27 cells around the candidate's.
    pub fn new(radius_m: f64) -> Self {
        Self {
            cell_m: radius_m * 1.001,
            kinds: Vec::new(),
        }
    }

    /// Records one iteration toward `target_m` of kind `strategy`; `touched` when it ended in a
    /// converged reading.
    pub fn record(&mut self, strategy: Strategy, target_m: DVec3, touched: bool) {
        let kind = match self.kinds.iter().position(|k| k.strategy == strategy) {
            Some(i) => &mut self.kinds[i],
            None => {
                self.kinds.push(KindOdds {
                    strategy,
                    tried: 0,
                    touched: 0,
                    targets: PointCells::new(self.cell_m),
                });
                let last = self.kinds.len() - 1;
                &mut self.kinds[last]
            }
        };
        kind.tried += 1;
        kind.touched += usize::from(touched);
        kind.targets.insert(target_m, (target_m, touched));
    }

    /// The chance that an iteration of kind `strategy` toward `target_m` ends in a converged
    /// reading: the kind's overall rate `p0 = (touched + 1) / (iterations + 2)` (Laplace's rule,
    /// 1/2 before any), refined by the iterations of that kind whose targets lay within
    /// `radius_m`: `(touched_near + a p0) / (near + a)`, `a` = [`ODDS_PRIOR_ITERATIONS`].
    pub fn chance(&self, strategy: Strategy, target_m: DVec3, radius_m: f64) -> f64 {
        let (mut tried, mut touched, mut near, mut touched_near) = (0, 0, 0usize, 0usize);
        if let Some(kind) = self.kinds.iter().find(|k| k.strategy == strategy) {
            (tried, touched) = (kind.tried, kind.touched);
            let radius_sq = radius_m * radius_m;
            for (target, hit) in kind.targets.near(target_m, radius_m) {
                if target.distance_squared(target_m) <= radius_sq {
                    near += 1;
                    touched_near += usize::from(*hit);
                }
            }
        }
        let overall = (touched as f64 + 1.0) / (tried as f64 + 2.0);
        (touched_near as f64 + ODDS_PRIOR_ITERATIONS * overall) / (near as f64 + ODDS_PRIOR_ITERATIONS)
    }
}

/// The expected gain of an iteration toward each candidate: its score (what a touch would teach;
/// a negative score, a touch expected to confuse, counts as nothing) times the chance the iteration
/// touches at all.
pub fn expected_gains(scores: &[f64], chances: &[f64]) -> Vec<f64> {
    scores
        .iter()
        .zip(chances)
        .map(|(score, chance)| score.max(0.0) * chance)
        .collect()
}

/// The index of the largest score, the first of equal ones; `None` for no scores. A NaN score never
/// wins.
pub fn best_candidate(scores: &[f64]) -> Option<usize> {
    let mut best: Option<usize> = None;
    for (i, s) in scores.iter().enumerate() {
        if s.is_nan() {
            continue;
        }
        if best.is_none_or(|b| *s > scores[b]) {
            best = Some(i);
        }
    }
    best.or((!scores.is_empty()).then_some(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stop_fires_once_one_guess_held_the_threshold_over_the_last_touches() {
        let p = |x| Probability::new(x).unwrap();
        let once = |x| ConfidenceStop::new(p(x)).held_over(NonZeroUsize::MIN);
        let trace: Vec<(usize, f64)> = [0.3, 0.6, 0.94, 0.95, 0.99, 0.5].map(|q| (0, q)).to_vec();
        // Held over one touch: the first touch that reaches the threshold.
        assert_eq!(once(0.95).touches_used(&trace, 10), Some(4));
        assert_eq!(once(0.9400001).touches_used(&trace, 10), Some(4));
        assert_eq!(once(0.94).touches_used(&trace, 10), Some(3));
        // Held over two (the default): the second touch in a row at or above it.
        assert_eq!(ConfidenceStop::new(p(0.95)).touches_used(&trace, 10), Some(5));
        assert_eq!(ConfidenceStop::new(p(0.94)).touches_used(&trace, 10), Some(4));
        assert_eq!(ConfidenceStop::new(p(0.96)).touches_used(&trace, 10), None);
        // A guess that changes while confident starts the count again.
        let switching = [(0, 0.97), (1, 0.97), (1, 0.4), (1, 0.96), (1, 0.98)];
        assert_eq!(ConfidenceStop::new(p(0.95)).touches_used(&switching, 10), Some(5));
        let three = NonZeroUsize::new(3).unwrap();
        assert_eq!(
            ConfidenceStop::new(p(0.95))
                .held_over(three)
                .touches_used(&switching, 10),
            None
        );
        // The budget is spent first.
        assert_eq!(once(0.95).touches_used(&trace, 3), None);
        assert_eq!(ConfidenceStop::new(p(0.95)).touches_used(&trace, 4), None);
        assert_eq!(once(1.0).touches_used(&trace, 10), None);
        assert!(!ConfidenceStop::new(p(0.5)).fires(&[]));
    }

    #[test]
    fn probabilities_outside_the_unit_interval_are_rejected() {
        for bad in ["0", "-0.1", "1.5", "nan", "x"] {
            assert!(bad.parse::<Probability>().is_err(), "{bad}");
        }
        assert_eq!("0.95".parse::<Probability>().map(Probability::get), Ok(0.95));
    }

    #[test]
    fn touch_odds_follow_the_neighbourhood_and_fall_back_on_the_kind() {
        let mut odds = TouchOdds::default();
        let here = DVec3::new(0.0, 0.0, 0.1);
        let far = DVec3::new(0.1, 0.0, 0.1);
        // Laplace's 1/2 before any iteration.
        assert_eq!(odds.chance(Strategy::Local, here, 0.02), 0.5);
        for _ in 0..4 {
            odds.record(Strategy::Local, here, true);
        }
        for _ in 0..4 {
            odds.record(Strategy::Global, far, false);
        }
        // Local: 4 of 4 overall, p0 = 5/6; near `here` (4 + 2 p0) / 6.
        let p0 = 5.0 / 6.0;
        let near = odds.chance(Strategy::Local, here, 0.02);
        assert!((near - (4.0 + 2.0 * p0) / 6.0).abs() < 1e-12);
        // Far from every local target: the kind's rate alone.
        assert!((odds.chance(Strategy::Local, far, 0.02) - p0).abs() < 1e-12);
        // Global: 0 of 4, p0 = 1/6; near `far` 2 p0 / 6, at `here` p0.
        assert!((odds.chance(Strategy::Global, far, 0.02) - 2.0 / 36.0).abs() < 1e-12);
        assert!((odds.chance(Strategy::Global, here, 0.02) - 1.0 / 6.0).abs() < 1e-12);
    }

    #[test]
    fn touch_odds_are_the_scan_of_every_recorded_iteration() {
        use rand::RngExt;
        let mut rng = crate::rng::rng(17);
        let mut odds = TouchOdds::new(0.025);
        let mut recorded = Vec::new();
        // What `chance` computed by scanning every iteration before the targets were binned.
        let scan = |recorded: &[(Strategy, DVec3, bool)], strategy: Strategy, at: DVec3, radius_m: f64| {
            let (mut tried, mut touched, mut near, mut touched_near) = (0.0, 0.0, 0.0, 0.0);
            for (kind, target, hit) in recorded {
                if *kind != strategy {
                    continue;
                }
                let hit = f64::from(u8::from(*hit));
                tried += 1.0;
                touched += hit;
                if target.distance_squared(at) <= radius_m * radius_m {
                    near += 1.0;
                    touched_near += hit;
                }
            }
            let overall = (touched + 1.0) / (tried + 2.0);
            (touched_near + ODDS_PRIOR_ITERATIONS * overall) / (near + ODDS_PRIOR_ITERATIONS)
        };
        let point = |rng: &mut crate::rng::Rng| {
            DVec3::new(
                rng.random_range(-0.1..0.1),
                rng.random_range(-0.1..0.1),
                rng.random_range(0.0..0.1),
            )
        };
        for i in 0..3000 {
            let strategy = if i % 3 == 0 {
                Strategy::Global
            } else {
                Strategy::Local
            };
            let target = point(&mut rng);
            let touched = rng.random_range(0.0..1.0) < 0.3;
            odds.record(strategy, target, touched);
            recorded.push((strategy, target, touched));
            if i % 97 == 0 {
                for radius_m in [0.01, 0.025, 0.06] {
                    for strategy in [Strategy::Local, Strategy::Global, Strategy::Active] {
                        let at = point(&mut rng);
                        let want = scan(&recorded, strategy, at, radius_m);
                        assert_eq!(
                            odds.chance(strategy, at, radius_m).to_bits(),
                            want.to_bits(),
                            "{i}, {radius_m}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn an_iteration_that_rarely_touches_loses_to_a_smaller_gain_that_does() {
        // A global candidate scoring the mutual information (0.4) with a 2% chance loses to a
        // local one scoring 0.1 with a 23% chance; a negative score is worth nothing.
        let gains = expected_gains(&[0.4, 0.1, -0.3], &[0.02, 0.23, 0.9]);
        assert_eq!(best_candidate(&gains), Some(1));
        assert_eq!(gains[2], 0.0);
    }

    #[test]
    fn the_best_candidate_is_the_first_of_the_largest_and_never_nan() {
        assert_eq!(best_candidate(&[0.1, 0.3, 0.3, 0.2]), Some(1));
        assert_eq!(best_candidate(&[f64::NAN, 0.0, -1.0]), Some(1));
        assert_eq!(best_candidate(&[]), None);
    }
}
