//! One object's active exploration, touch by touch, with the choice of each touch left to the
//! caller (a policy learning where to touch, a Gymnasium environment): the arm and the object in
//! their scene, the planner (Sec. III-A) that proposes where the next touch may go and carries the
//! pad there, and the belief over identity after every converged reading (Eq. 15-16).
//!
//! The scene and the planner are built as the `active` experiment builds them
//! ([`CollectPlan::planner_for`]: the object's own random and sensor-noise streams of the seed, the
//! object at the configured start, perturbed after every reading within the configured bounds), so
//! an episode's touches are
//! those the experiment's planner would make given the same choices. The model is shared
//! (`Arc<Recognizer>`), not borrowed, so that an episode can live as long as its caller wants (a
//! Python object); the recogniser's state is the images observed so far, replayed through a fresh
//! [`ActiveRecognition`] when a belief or a score is asked for (describing a few images costs far
//! less than one touch).

use std::sync::Arc;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::{ActiveRecognition, Touch, TouchError};
use crate::control::ControlError;
use crate::dataset::{Reading, Strategy};
use crate::explore::{CollectMode, CollectPlan, DEFAULT_CANDIDATES, Planner, PlannerConfig, SensorReader};
use crate::pose::PadPose;
use crate::recognize::{Belief, Recognizer, check_same_sensor};
use crate::sim::{Arm, ObjectSpec, PerturbationBounds, Scene, SimError, StartPose};
use crate::tactile::{SensorConfig, TactileImage};
use crate::valid::{Check, FieldChecks, RangeError, Valid};

/// How a [`TouchEpisode`] explores.
///
/// ```
/// use taction::active_touch::EpisodeConfig;
/// use taction::tactile::SensorConfig;
/// use taction::valid::Valid;
///
/// let config = EpisodeConfig::new(SensorConfig::paper());
/// assert!(Valid::new(config).is_ok());
/// let none = Valid::new(EpisodeConfig { candidates: 0, ..config }).unwrap_err();
/// assert_eq!(none.field, "candidates");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EpisodeConfig {
    /// The arm's sensor: the model's (checked by [`TouchEpisode::new`]); its noise stream is the
    /// episode's own.
    pub sensor: SensorConfig,
    /// The planner; its `local_probability` is L, with which each candidate is local.
    pub planner: Valid<PlannerConfig>,
    /// How far the object is moved after every reading (Sec. V-B4); `NONE`: it stays put.
    pub perturbation: PerturbationBounds,
    /// Where the object starts: where it was built (the default), or at a pose drawn from the
    /// episode's seed that neither the planner nor the policy is told, so that a policy cannot
    /// learn the canonical pose instead of the object. Left out of the JSON when canonical.
    #[serde(default, skip_serializing_if = "StartPose::is_canonical")]
    pub start_pose: StartPose,
    /// K: candidate targets offered before every touch, at least 1.
    pub candidates: usize,
    /// Readings within this distance of a candidate predict what a touch there shows, metres
    /// ([`InformationGain::neighbourhood_m`](super::InformationGain)).
    pub neighbourhood_m: f64,
}

impl EpisodeConfig {
    /// The `active` experiment's settings for `sensor`: the default planner (L = 0.5), the object
    /// fixed where it was built, [`DEFAULT_CANDIDATES`] candidates, the neighbourhood one grid cell
    /// of the planner.
    pub fn new(sensor: SensorConfig) -> Self {
        let planner = Valid::<PlannerConfig>::default();
        Self {
            sensor,
            neighbourhood_m: planner.grid_cell_m,
            planner,
            perturbation: PerturbationBounds::NONE,
            start_pose: StartPose::Canonical,
            candidates: DEFAULT_CANDIDATES,
        }
    }
}

/// K at most: far beyond any use (each candidate is scored before every touch), small enough that
/// the candidates' memory is never a concern.
pub const MAX_CANDIDATES: usize = 4096;

impl Check for EpisodeConfig {
    type Error = RangeError;

    fn check(&self) -> Result<(), RangeError> {
        let Self {
            // Checked against the model's at `TouchEpisode::new`, and by the scene's sensor.
            sensor: _,
            // Checked where they were built.
            planner: _,
            perturbation: _,
            start_pose: _,
            candidates,
            neighbourhood_m,
        } = *self;
        FieldChecks::of("episode config")
            .count(
                "candidates",
                candidates,
                (1..=MAX_CANDIDATES).contains(&candidates),
                "1 to 4096",
            )
            .real(
                "neighbourhood_m",
                neighbourhood_m,
                neighbourhood_m > 0.0,
                "(0, inf)",
            )
            .finish()
    }
}

/// One unknown object explored by the arm, one touch at a time, toward targets the caller picks
/// among the planner's candidates; the belief over identity follows every converged reading.
/// Everything is determined by the seed: two episodes of one model, object, configuration and
/// seed make the same candidates, touches and beliefs, bit for bit, given the same choices.
///
/// (Not run here: it needs a trained model file, `taction train`.)
///
/// ```no_run
/// use std::sync::Arc;
/// use taction::active_touch::{EpisodeConfig, TouchEpisode};
/// use taction::mesh::ObjectSet;
/// use taction::recognize::Recognizer;
/// use taction::sim::ObjectSpec;
/// use taction::valid::Valid;
///
/// let model = Arc::new(Recognizer::load("model.json".as_ref())?);
/// let rook = ObjectSpec::all_of(&ObjectSet::chess())?.remove(1);
/// let config = Valid::new(EpisodeConfig::new(*model.sensor()))?;
/// let mut episode = TouchEpisode::new(Arc::clone(&model), &rook, &config, 7)?;
/// // The information-gain policy: touch toward the candidate expected to teach the most.
/// while episode.touches() < 5 && episode.attempts() < 50 {
///     let best = episode.most_informative()?.unwrap_or(0);
///     if let Some(touch) = episode.touch(best)? {
///         println!("{:?}", touch.belief.probabilities());
///     }
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct TouchEpisode {
    model: Arc<Recognizer>,
    /// The object's index in the model's objects (the truth a guess is judged by).
    object_index: usize,
    object: String,
    neighbourhood_m: f64,
    candidates_per_touch: usize,
    scene: Scene,
    arm: Arm,
    planner: Planner<SensorReader>,
    /// The planner's proposals the next touch may go toward, and their points.
    proposals: Vec<(Strategy, DVec3)>,
    targets: Vec<DVec3>,
    /// The images of the converged readings, in order: the recogniser's state.
    observed: Vec<TactileImage>,
    belief: Belief,
    attempts: usize,
    last_attempt: Option<Reading>,
}

impl TouchEpisode {
    /// The arm before `object` on the table (at `config.start_pose`, perturbed after every reading
    /// within `config.perturbation`), the planner at its start and the first candidates drawn, the belief
    /// uniform. `object` must be one of the model's objects (its index there selects its random
    /// streams, as in the `active` experiment), and `config.sensor` the model's sensor.
    pub fn new(
        model: Arc<Recognizer>,
        object: &ObjectSpec,
        config: &Valid<EpisodeConfig>,
        seed: u64,
    ) -> Result<Self, TouchError> {
        check_same_sensor(model.sensor(), &config.sensor)?;
        let object_index = model
            .objects()
            .iter()
            .position(|o| *o == object.name)
            .ok_or_else(|| TouchError::UnknownObject {
                object: object.name.clone(),
                known: model.objects().join(", "),
            })?;
        let (scene, planner) = plan(config, seed).planner_for(object, object_index, config.planner)?;
        let arm = scene
            .arm()
            .cloned()
            .ok_or_else(|| ControlError::from(SimError::NoArm))?;
        let belief = ActiveRecognition::of(&model, config.neighbourhood_m)?.belief();
        let mut episode = Self {
            model,
            object_index,
            object: object.name.clone(),
            neighbourhood_m: config.neighbourhood_m,
            candidates_per_touch: config.candidates,
            scene,
            arm,
            planner,
            proposals: Vec::new(),
            targets: Vec::new(),
            observed: Vec::new(),
            belief,
            attempts: 0,
            last_attempt: None,
        };
        episode.draw_candidates();
        Ok(episode)
    }

    /// The targets the next touch may go toward (world frame, metres), in the planner's order: K
    /// drawn by its local/global rule (fewer only when its draws keep failing,
    /// [`Planner::propose_candidates`]).
    pub fn candidates(&self) -> &[DVec3] {
        &self.targets
    }

    /// The expected information gain of an iteration toward each candidate, nats: what a touch
    /// there would teach ([`InformationGain`](super::InformationGain)'s score given the readings
    /// so far) times the chance the iteration touches at all ([`touch_chances`](Self::touch_chances));
    /// the quantity the planner's active strategy maximises ([`crate::explore::expected_gains`]).
    pub fn gains(&self) -> Result<Vec<f64>, TouchError> {
        use crate::explore::TouchScorer;
        let scores = self.recognition()?.scorer().score(&self.targets);
        Ok(crate::explore::expected_gains(&scores, &self.touch_chances()))
    }

    /// The chance that a touch toward each candidate ends in a converged reading, judged from this
    /// episode's earlier touches ([`Planner::touch_chances`]).
    pub fn touch_chances(&self) -> Vec<f64> {
        self.planner.touch_chances(&self.proposals)
    }

    /// The information-gain policy's choice: the candidate of the largest expected gain (the first
    /// of equal ones, [`best_candidate`](crate::explore::best_candidate)); `None` with no candidate.
    pub fn most_informative(&self) -> Result<Option<usize>, TouchError> {
        Ok(crate::explore::best_candidate(&self.gains()?))
    }

    /// One planner iteration toward candidate `index` ([`Planner::touch_toward`]), then new
    /// candidates. `Some`: the iteration ended in a converged reading, which the belief now
    /// includes; `None`: it did not (no contact on the way, a collision, a reading that did not
    /// converge). An index beyond [`candidates`](Self::candidates) is an error, and touches nothing.
    pub fn touch(&mut self, index: usize) -> Result<Option<Touch>, TouchError> {
        let candidate = *self.proposals.get(index).ok_or(TouchError::NoSuchCandidate {
            index,
            candidates: self.proposals.len(),
        })?;
        let report = self
            .planner
            .touch_toward(&mut self.scene, &self.object, candidate)?;
        self.attempts += report.readings.len();
        self.last_attempt = report.readings.last().cloned();
        let touch = match report.readings.into_iter().find(Reading::is_converged) {
            Some(reading) => Some(self.observe(reading)?),
            None => None,
        };
        self.draw_candidates();
        Ok(touch)
    }

    /// Reading attempts so far, converged or not.
    pub fn attempts(&self) -> usize {
        self.attempts
    }

    /// Converged touches so far: the readings the belief includes.
    pub fn touches(&self) -> usize {
        self.observed.len()
    }

    /// The belief over the model's objects after the touches so far (uniform before any).
    pub fn belief(&self) -> &Belief {
        &self.belief
    }

    /// The model the belief is of.
    pub fn model(&self) -> &Arc<Recognizer> {
        &self.model
    }

    /// The explored object's name.
    pub fn object_name(&self) -> &str {
        &self.object
    }

    /// The explored object's index in the model's objects: the right guess.
    pub fn object_index(&self) -> usize {
        self.object_index
    }

    /// The image of the last converged touch; `None` before any.
    pub fn last_image(&self) -> Option<&TactileImage> {
        self.observed.last()
    }

    /// The last reading attempt, whatever its status (its cause says what ended it); `None` before
    /// any.
    pub fn last_attempt(&self) -> Option<&Reading> {
        self.last_attempt.as_ref()
    }

    /// Where the arm's pad is now.
    pub fn pad_pose(&self) -> PadPose {
        self.arm.pad_pose(self.scene.data())
    }

    /// The scene the arm explores in (to render or inspect it).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// A converged reading added to the belief.
    fn observe(&mut self, reading: Reading) -> Result<Touch, TouchError> {
        let mut recognition = self.recognition()?;
        let belief = recognition.observe(&reading.image)?;
        self.observed.push(reading.image.clone());
        self.belief = belief.clone();
        Ok(Touch { reading, belief })
    }

    /// The recogniser after the images observed so far, replayed in order.
    fn recognition(&self) -> Result<ActiveRecognition<'_>, TouchError> {
        let mut recognition = ActiveRecognition::of(&self.model, self.neighbourhood_m)?;
        for image in &self.observed {
            recognition.observe(image)?;
        }
        Ok(recognition)
    }

    fn draw_candidates(&mut self) {
        self.proposals = self.planner.propose_candidates(self.candidates_per_touch);
        self.targets = self.proposals.iter().map(|p| p.1).collect();
    }
}

/// The collection plan whose planner the episode drives: the `active` experiment's (the default
/// controllers, the configured sensor, planner, perturbation and start), seeded with `seed`.
fn plan(config: &EpisodeConfig, seed: u64) -> CollectPlan {
    CollectPlan {
        mode: CollectMode::Planner(config.planner),
        sensor: config.sensor,
        control: Valid::default(),
        perturbation: config.perturbation,
        readings_per_object: 0,
        seed,
        start_pose: config.start_pose,
    }
}
