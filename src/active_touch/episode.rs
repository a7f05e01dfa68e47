//! One object's active exploration, touch by touch, with the choice of each touch left to the
//! caller (a policy learning where to touch, a Gymnasium environment): the arm and the object in
//! their scene, the planner (Sec. III-A) that proposes where the next touch may go and carries the
//! pad there (a guarded touch by default, a reading attempt every action, two when the first met
//! the object and failed; or one planner iteration, [`TouchAction`]), and the belief over
//! identity after every converged reading (Eq. 15-16).
//!
//! The scene and the planner are built as the `active` experiment builds them
//! ([`CollectPlan::planner_for`]: the object's own random and sensor-noise streams of the seed, the
//! object at the configured start, perturbed after every reading within the configured bounds), so
//! an episode's touches are
//! those the experiment's planner would make given the same choices. The model is shared
//! (`Arc<Recognizer>`), not borrowed, so that an episode can live as long as its caller wants (a
//! Python object); the episode keeps one [`ActiveRecognition`] borrowing it (a self-referential
//! cell), which describes each reading once, when it arrives: a belief or a score costs the same
//! at the thirtieth touch as at the first.

use std::sync::Arc;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::{ActiveRecognition, Touch, TouchError};
use crate::bodies::FreeBody;
use crate::control::ControlError;
use crate::dataset::{Reading, Strategy};
use crate::explore::{
    CollectMode, CollectPlan, DEFAULT_CANDIDATES, ExplorationReport, Planner, PlannerConfig, SensorReader,
    recorded_perturbation,
};
use crate::locate::Contact;
use crate::pose::PadPose;
use crate::recognize::{Belief, Recognizer, check_same_sensor};
use crate::sim::{Arm, ObjectSpec, PerturbationBounds, Scene, SimError, StartPose, give_back_freed_memory};
use crate::tactile::{SensorConfig, TactileImage};
use crate::valid::{Check, FieldChecks, RangeError, Valid};

/// What one touch action of a [`TouchEpisode`] does with the candidate it is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TouchAction {
    /// A guarded touch through the candidate ([`Planner::guarded_touch`]): the pad moved along a
    /// ray until the covering meets a surface, then settled; a reading attempt every action (and
    /// another from above, three at most, after one that met the object and failed,
    /// `explore::earns_a_retry`).
    #[default]
    Guarded,
    /// One planner iteration toward the candidate ([`Planner::touch_toward`], Sec. III-A), what
    /// `taction/ActiveTouch-v0` steps: most iterations of a blind exploration meet nothing.
    Iteration,
}

impl TouchAction {
    /// The names the Python package and the environment take.
    pub const NAMES: [&'static str; 2] = ["guarded", "iteration"];

    /// Parses one of [`NAMES`](Self::NAMES).
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "guarded" => Some(Self::Guarded),
            "iteration" => Some(Self::Iteration),
            _ => None,
        }
    }
}

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
    /// What a touch toward a candidate does: a guarded touch (the default) or one planner
    /// iteration.
    #[serde(default)]
    pub touch: TouchAction,
    /// Readings within this distance of a candidate predict what a touch there shows, metres
    /// ([`InformationGain::neighbourhood_m`](super::InformationGain)).
    pub neighbourhood_m: f64,
    /// The object on a free joint, made of this (beyond the paper: it settles on the table, the
    /// arm's presses and a pushing perturbation move it); `None`, the paper's mocap object, which
    /// stays where it is put. Left out of the JSON when `None`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_object: Option<FreeBody>,
}

impl EpisodeConfig {
    /// The `active` experiment's settings for `sensor`: the default planner (L = 0.5), the object
    /// fixed where it was built, [`DEFAULT_CANDIDATES`] candidates, the neighbourhood one grid cell
    /// of the planner; each touch a guarded one.
    pub fn new(sensor: SensorConfig) -> Self {
        let planner = Valid::<PlannerConfig>::default();
        Self {
            sensor,
            neighbourhood_m: planner.grid_cell_m,
            planner,
            perturbation: PerturbationBounds::NONE,
            start_pose: StartPose::Canonical,
            candidates: DEFAULT_CANDIDATES,
            touch: TouchAction::Guarded,
            free_object: None,
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
            // Checked where they were built; the perturbation's act against the mount here.
            planner: _,
            perturbation,
            start_pose: _,
            touch: _,
            candidates,
            neighbourhood_m,
            free_object,
        } = *self;
        perturbation.check_act_on(free_object, "episode config")?;
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
    /// The recogniser after the converged readings so far, borrowing the model it shares.
    recognition: Recognition,
    /// The object's index in the model's objects (the truth a guess is judged by).
    object_index: usize,
    object: String,
    candidates_per_touch: usize,
    touch_action: TouchAction,
    scene: Scene,
    arm: Arm,
    planner: Planner<SensorReader>,
    /// The planner's proposals the next touch may go toward, and their points.
    proposals: Vec<(Strategy, DVec3)>,
    targets: Vec<DVec3>,
    /// The image of the last converged reading.
    last_image: Option<TactileImage>,
    /// The belief after the converged readings so far (its `readings` counts them).
    belief: Belief,
    attempts: usize,
    last_attempt: Option<Reading>,
}

impl TouchEpisode {
    /// The arm before `object` on the table (at `config.start_pose`, perturbed after every reading
    /// within `config.perturbation`), the planner at its start and the first candidates drawn, the belief
    /// uniform. `object` must be one of the model's objects (its index there selects its random
    /// streams, as in the `active` experiment), and `config.sensor` the model's sensor.
    ///
    /// The memory earlier episodes freed goes back to the system first
    /// ([`give_back_freed_memory`]): a run that makes episode after episode (an environment's
    /// resets) otherwise keeps every freed byte of them.
    pub fn new(
        model: Arc<Recognizer>,
        object: &ObjectSpec,
        config: &Valid<EpisodeConfig>,
        seed: u64,
    ) -> Result<Self, TouchError> {
        give_back_freed_memory();
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
        let recognition = Recognition::try_new(model, |model| {
            ActiveRecognition::of(
                model,
                config.neighbourhood_m,
                recorded_perturbation(&config.perturbation),
            )
        })?;
        let belief = recognition.borrow_dependent().belief();
        let mut episode = Self {
            recognition,
            object_index,
            object: object.name.clone(),
            candidates_per_touch: config.candidates,
            touch_action: config.touch,
            scene,
            arm,
            planner,
            proposals: Vec::new(),
            targets: Vec::new(),
            last_image: None,
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
        let scores = self.recognition.borrow_dependent().scorer().score(&self.targets);
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

    /// One touch toward candidate `index` as the configuration's [`TouchAction`] says (a guarded
    /// touch, [`Planner::guarded_touch`], or one planner iteration, [`Planner::touch_toward`]),
    /// then new candidates. `Some`: it ended in a converged reading, which the belief now
    /// includes; `None`: it did not ([`last_attempt`](Self::last_attempt) says how a guarded touch
    /// ended; an iteration may also have met nothing at all). An index beyond
    /// [`candidates`](Self::candidates) is an error, and touches nothing.
    pub fn touch(&mut self, index: usize) -> Result<Option<Touch>, TouchError> {
        let candidate = *self.proposals.get(index).ok_or(TouchError::NoSuchCandidate {
            index,
            candidates: self.proposals.len(),
        })?;
        let report = self.touch_toward(candidate)?;
        self.last_attempt = report.readings.last().cloned();
        // The first converged reading is the touch; every other attempt gave the belief nothing
        // but time for a perturbed object to move.
        let mut touch = None;
        for reading in report.readings {
            if touch.is_none() && reading.is_converged() {
                touch = Some(self.observe(reading)?);
            } else {
                self.recognition
                    .with_dependent_mut(|_, recognition| recognition.missed());
            }
            self.attempts += 1;
        }
        self.draw_candidates();
        Ok(touch)
    }

    /// Reading attempts so far, converged or not.
    pub fn attempts(&self) -> usize {
        self.attempts
    }

    /// Converged touches so far: the readings the belief includes.
    pub fn touches(&self) -> usize {
        self.belief.readings
    }

    /// The belief over the model's objects after the touches so far (uniform before any).
    pub fn belief(&self) -> &Belief {
        &self.belief
    }

    /// The model the belief is of.
    pub fn model(&self) -> &Arc<Recognizer> {
        self.recognition.borrow_owner()
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
        self.last_image.as_ref()
    }

    /// Where the last converged touch met the surface: the pressed taxels' surface point and the
    /// outward normal ([`Contact::of_image`], without the model's contact noise); `None` before
    /// any.
    pub fn last_contact(&self) -> Option<Contact> {
        Contact::of_image(self.last_image.as_ref()?, self.model().sensor())
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

    /// What the configured [`TouchAction`] does toward `candidate`.
    fn touch_toward(&mut self, candidate: (Strategy, DVec3)) -> Result<ExplorationReport, ControlError> {
        match self.touch_action {
            TouchAction::Guarded => self
                .planner
                .guarded_touch(&mut self.scene, &self.object, candidate),
            TouchAction::Iteration => self
                .planner
                .touch_toward(&mut self.scene, &self.object, candidate),
        }
    }

    /// A converged reading added to the belief: described once, here.
    fn observe(&mut self, reading: Reading) -> Result<Touch, TouchError> {
        let belief = self
            .recognition
            .with_dependent_mut(|_, recognition| recognition.observe(&reading.image))?;
        self.last_image = Some(reading.image.clone());
        self.belief = belief.clone();
        Ok(Touch {
            reading,
            belief,
            attempt: self.attempts,
        })
    }

    fn draw_candidates(&mut self) {
        self.proposals = self.planner.propose_candidates(self.candidates_per_touch);
        self.targets = self.proposals.iter().map(|p| p.1).collect();
    }
}

self_cell::self_cell!(
    /// The shared model and the recogniser of one episode's readings, which borrows it.
    struct Recognition {
        owner: Arc<Recognizer>,
        #[covariant]
        dependent: ActiveRecognition,
    }
);

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
        free_object: config.free_object,
    }
}
