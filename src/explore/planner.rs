//! The sampling-based exploration planner (Sec. III-A): blind test-time exploration with the arm.
//!
//! The planner knows only the workspace box. Each iteration picks the local strategy with probability
//! L (once a reading exists), else the global one:
//! - global: a target p uniform in the workspace, expanded from the tree vertex whose pad is nearest p
//!   (RRT-style, pulling exploration toward new places);
//! - local: a target p in a small ball around a reading location drawn from a sparsely read grid cell
//!   ([`ReadingGrid`]), expanded from the nearest vertex.
//!
//! - active (beyond the paper, [`crate::explore::active`]): several targets drawn by the rule above,
//!   the one a [`TouchScorer`](crate::explore::TouchScorer) expects to be most informative expanded.
//!
//! Expansion takes small steps: from the pad toward p to a nearby point p', inverse kinematics for p',
//! a slow guarded `move_to` while the sensor is watched. When the sensor feels the object on the way,
//! surface contact control takes over (Sec. III-B) and its reading is recorded; a converged reading's
//! location enters the grid, and the configuration lifted off the surface along the pad normal joins the
//! tree, so local expansions start facing the surface they read.
//!
//! Returning to a vertex: the arm's state is reset to the vertex configuration. A real arm would retrace
//! the tree's collision-free edges back to it; simulating that retrace would cost time and change no
//! reading, so it is skipped.
//!
//! Motions ([`PlannerConfig::execution`], see `sim::arm`): by default edges are checked the way
//! sampling-based planners check them, MuJoCo's kinematics and collision detection at samples of the
//! joint-space segment, and the arm is placed at rest at the end; [`Execution::Servo`] steps the
//! position servos through MuJoCo's dynamics instead (the behaviour before, kept for comparison). On a
//! kinematic edge the sensor is watched where it can feel something: while MuJoCo's distance between
//! the pad's rigid back and every geom outside the arm exceeds the covering's reach beyond the back,
//! no ray of the covering can meet a solid, so the plugin would read zero (and noise below the
//! contact threshold); samples there are spaced by that clearance (conservative advancement) and the
//! plugin is not evaluated. Closer, the plugin is read at every sample, the pad advancing at most one
//! Approach step (`approach_step_thickness * t`) between readings, so the first contact is felt
//! within a fraction of the covering rather than after the rigid back has met the surface (which a
//! control interval of the servo execution could overshoot). Every reading still comes from the
//! sensor plugin in the MuJoCo scene.
//!
//! The vertex added after a converged reading is the configuration the arm actually reached lifting
//! the pad off the surface along its normal (a checked motion), so the tree holds only collision-free
//! configurations.

mod guarded;

pub use guarded::{AXIS_HEIGHT_FRACTION, ApproachRay, MAX_ATTEMPTS, earns_a_retry};

use glam::DVec3;
use rand::RngExt;
use serde::{Deserialize, Serialize};

use crate::control::arm_pad::ArmPad;
use crate::control::{ControlError, ReadTactile, settle};
use crate::dataset::{AttemptCause, CauseKind, ContactStatus, Reading, Strategy};
use crate::explore::active::{ActiveGuidance, TouchOdds, best_candidate, expected_gains};
use crate::explore::grid::ReadingGrid;
use crate::explore::report::{ExplorationReport, aborted_reading, attempt_reading};
use crate::explore::setup::TouchSetup;
use crate::explore::tree::ExplorationTree;
use crate::mesh::SizeLimit;
use crate::pose::PadPose;
use crate::rng::Rng;
use crate::sim::arm::{Execution, PAD_SITE, Watch};
use crate::sim::mjcf::TABLE_TOP_Z_M;
use crate::sim::{
    Arm, Collision, IkOptions, InverseKinematics, MoveOptions, MoveOutcome, ObjectSpec, PadTarget, Scene,
    SceneState,
};
use crate::tactile::{CoveringSensor, SensorConfig, TactileImage};
use crate::valid::{Check, FieldChecks, RangeError, Valid};

/// The planner's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlannerConfig {
    /// Lower corner of the workspace box, metres (the only thing the planner knows of the object). Its
    /// floor is 2 cm above the table: targets lower than that send the pad onto the table.
    pub workspace_min_m: DVec3,
    /// Upper corner of the workspace box, metres.
    pub workspace_max_m: DVec3,
    /// L: probability of the local strategy at each iteration (Sec. V-B3).
    pub local_probability: f64,
    /// Length of one expansion step toward the target, metres.
    pub step_m: f64,
    /// Expansion steps per iteration at most.
    pub max_steps_per_iteration: usize,
    /// Radius of the "small sphere" around a reading location for local targets, metres.
    pub local_radius_m: f64,
    /// Side of the local strategy's grid cells, metres.
    pub grid_cell_m: f64,
    /// Distance the pad is lifted off the surface after a reading, metres.
    pub lift_off_m: f64,
    /// Largest turn of the pad normal toward the direction of motion per global expansion step,
    /// radians: the pad comes to lead the motion (so it meets the object with its covering) without
    /// demanding a wrist flip in one step.
    pub max_turn_per_step_rad: f64,
    /// Iterations allowed before giving up on reaching the requested number of readings.
    pub max_iterations: usize,
    /// How the arm's motions are executed: MuJoCo-checked kinematic edges (default) or servo
    /// dynamics (the earlier behaviour; see the module documentation).
    pub execution: Execution,
}

/// Draws of the paper's rule per candidate asked of [`Planner::propose_candidates`] at most: a
/// local draw fails only when no grid cell is found, so four draws per candidate leave room for
/// failures without letting a caller loop forever.
pub const PROPOSAL_DRAWS_PER_CANDIDATE: usize = 4;

/// Planner iterations allowed per converged reading asked for. The default budget (20,000
/// iterations) was sized for the paper's 100 test readings per object; a training set from the
/// arm asks for ten times as many, and a budget that does not grow with it stops short (the
/// measurements are in `docs/measurements.md`, "Training that matches the arm").
pub const ITERATIONS_PER_READING: usize = 200;

impl PlannerConfig {
    /// The iteration budget for `readings` converged readings per object: [`ITERATIONS_PER_READING`]
    /// each, and never less than the default's.
    pub fn iterations_for(readings: usize) -> usize {
        readings
            .saturating_mul(ITERATIONS_PER_READING)
            .max(Self::default().max_iterations)
    }

    /// The planner `collect --mode planner` runs for `readings` converged readings per object of
    /// `objects`: the defaults with local probability L = `local_probability`, `max_iterations`
    /// or else [`iterations_for`](Self::iterations_for) `readings`, the workspace
    /// [`fitted_to`](Self::fitted_to) the objects. Checked where it is used.
    pub fn for_collection(
        objects: &[ObjectSpec],
        readings: usize,
        local_probability: f64,
        max_iterations: Option<usize>,
    ) -> Self {
        Self {
            max_iterations: max_iterations.unwrap_or_else(|| Self::iterations_for(readings)),
            ..Self::exploring(objects, local_probability)
        }
    }

    /// The defaults with local probability L = `local_probability` and the workspace
    /// [`fitted_to`](Self::fitted_to) `objects`: the planner of every exploration of those objects
    /// (the demo's, the environment's episodes, a collection's before its iteration budget).
    pub fn exploring(objects: &[ObjectSpec], local_probability: f64) -> Self {
        Self {
            local_probability,
            ..Self::default()
        }
        .fitted_to(objects)
    }

    /// The largest object the arm explores: the diagonal of the workspace box (Sec. III-A), the
    /// only region the planner's targets are drawn from.
    pub fn object_size_limit(&self) -> SizeLimit {
        SizeLimit {
            max_diagonal_m: (self.workspace_max_m - self.workspace_min_m).length(),
            reason: "the arm's workspace",
        }
    }
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            workspace_min_m: DVec3::new(-0.15, -0.15, 0.02),
            workspace_max_m: DVec3::new(0.15, 0.15, 0.22),
            local_probability: 0.5,
            step_m: 0.02,
            max_steps_per_iteration: 12,
            local_radius_m: 0.025,
            grid_cell_m: 0.03,
            lift_off_m: 0.01,
            max_turn_per_step_rad: 30f64.to_radians(),
            max_iterations: 20_000,
            execution: Execution::Kinematic,
        }
    }
}

/// Room left around the objects' bounding spheres by [`PlannerConfig::fitted_to`], metres: enough for
/// the pad to approach a surface from outside along any direction.
pub const WORKSPACE_MARGIN_M: f64 = 0.03;

impl PlannerConfig {
    /// The workspace box shrunk to where `objects` can be: the union of their bounding spheres as
    /// they rest (a sphere, so that any rotation of an object by a perturbation stays inside) grown
    /// by [`WORKSPACE_MARGIN_M`], within the configured box (what the arm reaches; its floor stays
    /// above the table). The box is the set's, the same whichever object is explored: the planner is
    /// still told nothing of the object's identity, pose or shape (Sec. III-A). Fewer global targets
    /// fall in empty space, which is what bounds the global strategy (L = 0) in the full box
    /// (`docs/guide.md`, "Exploration"; `tests/explore_shapes.rs` checks every `shapes` object).
    pub fn fitted_to(self, objects: &[ObjectSpec]) -> Self {
        let spheres = objects.iter().filter_map(|o| {
            let (lo, hi) = o.mesh.bounds()?;
            let center = o.pose.transform_point((lo + hi) * 0.5);
            Some((center, 0.5 * (hi - lo).length() + WORKSPACE_MARGIN_M))
        });
        let Some((lo, hi)) = spheres
            .map(|(c, r)| (c - DVec3::splat(r), c + DVec3::splat(r)))
            .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
        else {
            return self;
        };
        let min = lo.max(self.workspace_min_m);
        let max = hi.min(self.workspace_max_m);
        if !min.cmplt(max).all() {
            return self;
        }
        Self {
            workspace_min_m: min,
            workspace_max_m: max,
            ..self
        }
    }
}

impl Check for PlannerConfig {
    type Error = RangeError;

    /// Every field against its range; the error names the first offender.
    fn check(&self) -> Result<(), RangeError> {
        let Self {
            workspace_min_m,
            workspace_max_m,
            local_probability,
            step_m,
            max_steps_per_iteration,
            local_radius_m,
            grid_cell_m,
            lift_off_m,
            max_turn_per_step_rad,
            max_iterations,
            execution: _,
        } = *self;
        let positive = |v: f64| v > 0.0;
        FieldChecks::of("planner config")
            .that(
                "workspace_min_m",
                workspace_min_m,
                workspace_min_m.is_finite()
                    && workspace_max_m.is_finite()
                    && workspace_min_m.cmplt(workspace_max_m).all(),
                "finite and below workspace_max_m on every axis",
            )
            .real(
                "local_probability",
                local_probability,
                (0.0..=1.0).contains(&local_probability),
                "[0, 1]",
            )
            .real("step_m", step_m, positive(step_m), "(0, inf)")
            .count(
                "max_steps_per_iteration",
                max_steps_per_iteration,
                max_steps_per_iteration > 0,
                "1 or more",
            )
            .real(
                "local_radius_m",
                local_radius_m,
                positive(local_radius_m),
                "(0, inf)",
            )
            .real("grid_cell_m", grid_cell_m, positive(grid_cell_m), "(0, inf)")
            .real("lift_off_m", lift_off_m, positive(lift_off_m), "(0, inf)")
            .real(
                "max_turn_per_step_rad",
                max_turn_per_step_rad,
                max_turn_per_step_rad > 0.0 && max_turn_per_step_rad <= std::f64::consts::PI,
                "(0, pi]",
            )
            .count("max_iterations", max_iterations, max_iterations > 0, "1 or more")
            .finish()
    }
}

/// Where one iteration expands: from tree vertex `vertex` toward `target`, carried as `strategy`
/// says, its reading of `object` tagged `label`; a physics fault while settling restores
/// `checkpoint`.
struct Expansion<'a> {
    vertex: usize,
    strategy: Strategy,
    label: Strategy,
    target: DVec3,
    object: &'a str,
    checkpoint: &'a SceneState,
    /// Expansion steps at most.
    max_steps: usize,
    /// A guarded touch's motion (`planner/guarded.rs`), an Approach along the pad's normal: the
    /// object reaching the pad's rigid back ([`Collision::back_on_object`]) hands over to the
    /// controllers, as a rigid contact does in their Approach, rather than stopping the expansion
    /// as a collision (the planner's collision-free motions, Sec. III-A); and the controllers'
    /// turns are limited by the table ([`ArmPad::limited_by_the_table`]). The planner's own
    /// iterations keep the paper's behaviour, so its experiments do not move.
    guarded: bool,
}

/// How an expansion ended.
enum ExpansionEnd {
    /// The sensor felt a surface and the controllers' reading was recorded.
    Read,
    /// A step's motion collided.
    Collided(Collision),
    /// A step had no inverse-kinematics solution.
    Unreachable,
    /// The target was reached, or the steps ran out, and nothing was felt.
    Nothing,
}

/// What a run records as it goes: every reading attempt, and whom to tell of each converged one.
struct Record<'r> {
    report: ExplorationReport,
    on_converged: &'r mut dyn FnMut(),
}

impl Record<'_> {
    /// Records `reading`, taken in `scene`: a free object's pose there is the reading's pose after
    /// its touch.
    fn push(&mut self, mut reading: Reading, scene: &Scene) {
        if scene.object_is_free() {
            reading.object_pose_after = scene.object_pose();
        }
        let converged = reading.is_converged();
        self.report.readings.push(reading);
        if converged {
            (self.on_converged)();
        }
    }
}

/// The planner's state for one exploration run.
pub struct Planner<R> {
    config: Valid<PlannerConfig>,
    setup: TouchSetup,
    /// Precise solver for the controllers' small commands.
    ik: InverseKinematics,
    /// Solver for expansion steps, where a fraction of a millimetre does not matter.
    expansion_ik: InverseKinematics,
    motion: MoveOptions,
    expansion_motion: MoveOptions,
    /// How far the covering reaches beyond the pad's rigid back, metres: a clearance of the back above
    /// this means the sensor cannot feel anything.
    covering_reach_m: f64,
    tree: ExplorationTree,
    grid: ReadingGrid,
    /// Where guided iterations touched and where they did not (the active strategy's
    /// `P(reading | target)`, `explore/active.rs`).
    odds: TouchOdds,
    rng: Rng,
    reader: R,
    /// The covering sensor on the pad, which tells the planner whether a stopped expansion step
    /// met the object with the pad's rigid back; `None` in a scene without one.
    covering: Option<CoveringSensor>,
}

/// Tight solver and servo settings for controller commands: sub-millimetre Press steps must be executed
/// to a few hundredths of a millimetre. Near convergence Press commands steps of `t k_p e`, e.g.
/// 1.2 mm x 0.8 x 0.015 = 15 um, so the solver must be far tighter than that: with a 20 um tolerance
/// the warm-started solver returned the current configuration unchanged and Press repeated the same
/// command until its budget ran out.
pub fn precise_motion() -> (IkOptions, MoveOptions) {
    (
        IkOptions {
            position_tolerance_m: 1e-6,
            angle_tolerance_rad: 0.002_f64.to_radians(),
            ..IkOptions::default()
        },
        MoveOptions {
            tolerance_rad: 5e-5,
            settle_intervals: 300,
            ..MoveOptions::default()
        },
    )
}

/// The controller-command settings of [`precise_motion`] with kinematic execution, checked every
/// `max_pad_step_m` of pad travel (controller commands are sub-millimetre, so usually one sample).
pub fn precise_kinematic_motion(max_pad_step_m: f64) -> (IkOptions, MoveOptions) {
    let (ik, motion) = precise_motion();
    (
        ik,
        MoveOptions {
            max_pad_step_m,
            ..motion.kinematic()
        },
    )
}

/// How far the covering of `sensor` reaches beyond the rigid back `back_half_size_m` (the MuJoCo box
/// half-sizes: depth along the normal, then the two in-plane half-widths) of the arm: the largest
/// distance from a covering point to the back.
pub fn covering_reach_m(sensor: &SensorConfig, back_half_size_m: [f64; 3]) -> f64 {
    let half_face = back_half_size_m[1].min(back_half_size_m[2]);
    let over_w = (0.5 * sensor.pad_width_m - half_face).max(0.0);
    let over_h = (0.5 * sensor.pad_height_m - half_face).max(0.0);
    (over_w * over_w + over_h * over_h + sensor.thickness_m * sensor.thickness_m).sqrt()
}

impl<R> Planner<R>
where
    R: ReadTactile,
{
    /// A planner for `scene` (which must have an arm), starting from the arm's current configuration.
    pub fn new(
        scene: &Scene,
        config: Valid<PlannerConfig>,
        setup: TouchSetup,
        rng: Rng,
        reader: R,
    ) -> Result<Self, ControlError> {
        let arm = scene.arm().cloned().ok_or(crate::sim::SimError::NoArm)?;
        let t = setup.sensor.thickness_m;
        let (ik_options, motion, expansion_motion) = match config.execution {
            Execution::Servo => {
                let (ik, motion) = precise_motion();
                (ik, motion, MoveOptions::default())
            }
            Execution::Kinematic => {
                let (ik, motion) = precise_kinematic_motion(0.125 * t);
                (ik, motion, MoveOptions::default().kinematic())
            }
        };
        let ik = InverseKinematics::for_scene(scene, ik_options)?;
        let expansion_ik = InverseKinematics::for_scene(scene, IkOptions::default())?;
        let covering_reach_m = match arm.back_geom() {
            Some(g) => covering_reach_m(&setup.sensor, scene.model().geom_size()[g]),
            None => f64::INFINITY,
        };
        let q = arm.q(scene.data());
        let pad = arm.pad_pose(scene.data());
        Ok(Self {
            config,
            setup,
            ik,
            expansion_ik,
            motion,
            expansion_motion,
            covering_reach_m,
            tree: ExplorationTree::new(q, pad.center_m, pad.normal),
            grid: ReadingGrid::new(config.workspace_min_m, config.grid_cell_m),
            odds: TouchOdds::new(config.local_radius_m),
            rng,
            reader,
            covering: CoveringSensor::on_site(scene.model(), PAD_SITE).ok(),
        })
    }

    pub fn tree(&self) -> &ExplorationTree {
        &self.tree
    }

    pub fn grid(&self) -> &ReadingGrid {
        &self.grid
    }

    /// Explores until `converged_target` converged readings (or the iteration budget); every reading
    /// attempt, whatever its status, is returned in order.
    pub fn explore(
        &mut self,
        scene: &mut Scene,
        object: &str,
        converged_target: usize,
    ) -> Result<ExplorationReport, ControlError> {
        self.explore_reporting(scene, object, converged_target, &mut || {})
    }

    /// [`explore`](Self::explore), running `on_converged` after each converged reading (progress
    /// reports).
    pub fn explore_reporting(
        &mut self,
        scene: &mut Scene,
        object: &str,
        converged_target: usize,
        on_converged: &mut dyn FnMut(),
    ) -> Result<ExplorationReport, ControlError> {
        self.explore_guided(scene, object, converged_target, None, on_converged)
    }

    /// [`explore_reporting`](Self::explore_reporting) with the active strategy when `guidance` is
    /// given (`explore/active.rs`): each iteration draws `guidance.candidates` targets by the
    /// local/global rule and expands toward the one the scorer rates highest; the readings are
    /// tagged [`Strategy::Active`].
    pub fn explore_guided(
        &mut self,
        scene: &mut Scene,
        object: &str,
        converged_target: usize,
        guidance: Option<ActiveGuidance<'_>>,
        on_converged: &mut dyn FnMut(),
    ) -> Result<ExplorationReport, ControlError> {
        let arm = scene.arm().cloned().ok_or(crate::sim::SimError::NoArm)?;
        let mut record = Record {
            report: ExplorationReport::default(),
            on_converged,
        };
        while record.report.converged() < converged_target
            && record.report.iterations < self.config.max_iterations
        {
            record.report.iterations += 1;
            let Some((strategy, target)) = self.choose_target(guidance) else {
                continue;
            };
            // How the pad is carried toward the target follows the proposal's kind; the reading
            // is tagged with the strategy that chose it.
            let label = if guidance.is_some() {
                Strategy::Active
            } else {
                strategy
            };
            // Only guided iterations feed the odds; a blind run does not count its readings here.
            let converged_before = guidance.map(|_| record.report.converged());
            self.iterate_toward(scene, &arm, object, (strategy, target), label, &mut record)?;
            if let Some(before) = converged_before {
                let touched = record.report.converged() > before;
                self.odds.record(strategy, target, touched);
            }
        }
        Ok(record.report)
    }

    /// `k` targets by the paper's rule (each local with probability L once a reading exists, else
    /// global: what one iteration of [`explore`](Self::explore) draws), in the order drawn, for a caller that chooses among them
    /// itself (an active-touch policy). A local draw that finds no cell gives nothing and is drawn
    /// again, at most [`PROPOSAL_DRAWS_PER_CANDIDATE`]` * k` draws in all, so fewer than `k` come
    /// back only when the draws keep failing (never while a global draw is possible, L < 1).
    pub fn propose_candidates(&mut self, k: usize) -> Vec<(Strategy, DVec3)> {
        let mut proposals = Vec::with_capacity(k);
        for _ in 0..k.saturating_mul(PROPOSAL_DRAWS_PER_CANDIDATE) {
            if proposals.len() == k {
                break;
            }
            proposals.extend(self.propose());
        }
        proposals
    }

    /// Exactly one planner iteration (Sec. III-A) toward `candidate` (a proposal of
    /// [`propose_candidates`](Self::propose_candidates), or any target and the strategy that
    /// carries the pad toward it): from the nearest tree vertex, the expansion in small steps and,
    /// where the sensor feels the object, surface contact control; its reading, if any, is tagged
    /// with `candidate.0`. The same iteration as [`explore_guided`](Self::explore_guided)'s: a
    /// physics fault restores the world and is counted in the report's `expansion_stops`.
    pub fn touch_toward(
        &mut self,
        scene: &mut Scene,
        object: &str,
        candidate: (Strategy, DVec3),
    ) -> Result<ExplorationReport, ControlError> {
        let arm = scene.arm().cloned().ok_or(crate::sim::SimError::NoArm)?;
        let mut record = Record {
            report: ExplorationReport {
                iterations: 1,
                ..ExplorationReport::default()
            },
            on_converged: &mut || {},
        };
        self.iterate_toward(scene, &arm, object, candidate, candidate.0, &mut record)?;
        self.odds
            .record(candidate.0, candidate.1, record.report.converged() > 0);
        Ok(record.report)
    }

    /// One iteration toward `target` (its strategy, its point), the reading tagged `label`: return
    /// to the tree vertex nearest the target, then expand (a physics fault anywhere puts the world
    /// back at the vertex, the object as it lay, and is counted; exploration goes on).
    fn iterate_toward(
        &mut self,
        scene: &mut Scene,
        arm: &Arm,
        object: &str,
        (strategy, target): (Strategy, DVec3),
        label: Strategy,
        record: &mut Record<'_>,
    ) -> Result<(), ControlError> {
        let vertex = self.tree.nearest(target);
        if !self.return_to(scene, arm, vertex) {
            return Ok(());
        }
        let checkpoint = scene.checkpoint()?;
        let expansion = Expansion {
            vertex,
            strategy,
            label,
            target,
            object,
            checkpoint: &checkpoint,
            max_steps: self.config.max_steps_per_iteration,
            guarded: false,
        };
        match self.expand(scene, arm, &expansion, record) {
            Ok(ExpansionEnd::Collided(c)) => {
                *record
                    .report
                    .expansion_stops
                    .entry(AttemptCause::from(&c).kind())
                    .or_insert(0) += 1;
                Ok(())
            }
            Ok(ExpansionEnd::Unreachable) => {
                record.report.unreachable_steps += 1;
                Ok(())
            }
            Ok(ExpansionEnd::Read | ExpansionEnd::Nothing) => Ok(()),
            Err(e) if e.is_physics_fault() => {
                scene.restore(&checkpoint)?;
                *record
                    .report
                    .expansion_stops
                    .entry(CauseKind::PhysicsFault)
                    .or_insert(0) += 1;
                Ok(())
            }
            Err(e) => Err(e),
        }
    }

    /// The iteration's target: one proposal by the paper's rule ([`propose`](Self::propose)), or
    /// with `guidance` the one of its candidates the scorer rates highest. `None`: no target this
    /// iteration.
    fn choose_target(&mut self, guidance: Option<ActiveGuidance<'_>>) -> Option<(Strategy, DVec3)> {
        let Some(guide) = guidance else {
            return self.propose();
        };
        let proposals: Vec<(Strategy, DVec3)> = (0..guide.candidates.max(1))
            .filter_map(|_| self.propose())
            .collect();
        let targets: Vec<DVec3> = proposals.iter().map(|p| p.1).collect();
        let gains = expected_gains(&guide.scorer.score(&targets), &self.touch_chances(&proposals));
        let best = best_candidate(&gains)?;
        Some(proposals[best])
    }

    /// For each candidate (its kind, its target), the chance that an iteration toward it ends in a
    /// converged reading, judged from this planner's earlier guided iterations (and
    /// [`touch_toward`](Self::touch_toward)'s) whose targets lay within the local radius
    /// ([`TouchOdds::chance`]).
    pub fn touch_chances(&self, candidates: &[(Strategy, DVec3)]) -> Vec<f64> {
        candidates
            .iter()
            .map(|&(strategy, target)| self.odds.chance(strategy, target, self.config.local_radius_m))
            .collect()
    }

    /// Resets the arm to tree vertex `vertex` (Sec. III-A; the module docs say why it is not
    /// retraced); `false` when a perturbation has since moved the object into the arm there: the
    /// vertex is blocked, expanding from it would only collide again.
    fn return_to(&mut self, scene: &mut Scene, arm: &Arm, vertex: usize) -> bool {
        arm.place(scene, &self.tree.vertices()[vertex].q.clone());
        if vertex != 0 && arm.collision(scene).is_some() {
            self.tree.block(vertex);
            return false;
        }
        true
    }

    /// One iteration's expansion toward `expansion.target` in small steps, until a step is stopped
    /// (a collision, no IK solution) or the sensor feels something, when surface contact control
    /// takes over and its reading is recorded (a physics fault there: an `aborted` reading, the
    /// world restored to the checkpoint). How it ended is the caller's to count; so is a physics
    /// fault elsewhere.
    fn expand(
        &mut self,
        scene: &mut Scene,
        arm: &Arm,
        expansion: &Expansion<'_>,
        record: &mut Record<'_>,
    ) -> Result<ExpansionEnd, ControlError> {
        let threshold = self.setup.control.effective_contact_threshold();
        let mut vertex = expansion.vertex;
        let facing = self.tree.vertices()[vertex].pad_normal;
        for _ in 0..expansion.max_steps {
            let pad = arm.pad_pose(scene.data());
            let Some(step) = self.step_toward(&pad, expansion, facing) else {
                break;
            };
            let Some(q) = self.solve_step(scene, arm, &step, pad.normal) else {
                return Ok(ExpansionEnd::Unreachable);
            };
            let (outcome, sensed) = self.expand_to(scene, arm, &q, threshold)?;
            let felt = match outcome {
                MoveOutcome::Collided(c) if expansion.guarded && c == Collision::back_on_object() => true,
                MoveOutcome::Collided(c) => return Ok(ExpansionEnd::Collided(c)),
                MoveOutcome::Reached | MoveOutcome::Stopped => sensed,
            };
            if !felt {
                let pad = arm.pad_pose(scene.data());
                vertex = self
                    .tree
                    .add(vertex, arm.q(scene.data()), pad.center_m, pad.normal);
                continue;
            }
            self.read_surface(scene, arm, expansion, (vertex, pad), record)?;
            return Ok(ExpansionEnd::Read);
        }
        Ok(ExpansionEnd::Nothing)
    }

    /// The next step from the pad at `pad` toward the expansion's target: at most `step_m` along
    /// the way, the pad facing the vertex's surface on a local expansion, else turned toward the
    /// motion (at most `max_turn_per_step_rad`). `None` once the target is reached.
    fn step_toward(&self, pad: &PadPose, expansion: &Expansion<'_>, facing: DVec3) -> Option<PadTarget> {
        let to_target = expansion.target - pad.center_m;
        let distance = to_target.length();
        if distance < 1e-3 {
            return None;
        }
        let direction = to_target / distance;
        let next = pad.center_m + direction * distance.min(self.config.step_m);
        let normal = match expansion.strategy {
            Strategy::Local => facing,
            _ => turn_toward(pad.normal, direction, self.config.max_turn_per_step_rad),
        };
        Some(PadTarget {
            center_m: next,
            normal,
        })
    }

    /// The arm's configuration for `step`; if the turned pad cannot be reached, the step keeping
    /// the pad's orientation `normal`. `None`: no solution either way.
    fn solve_step(&mut self, scene: &Scene, arm: &Arm, step: &PadTarget, normal: DVec3) -> Option<Vec<f64>> {
        let start = arm.q(scene.data());
        self.expansion_ik
            .solve(step, &start)
            .or_else(|_| {
                self.expansion_ik.solve(
                    &PadTarget {
                        center_m: step.center_m,
                        normal,
                    },
                    &start,
                )
            })
            .ok()
    }

    /// The sensor felt the object (Sec. III-B): the controllers settle a reading here (a reading
    /// pressed on the table relabelled a collision), a converged one enters the grid and its
    /// lifted-off configuration the tree (as a child of `at.0`; `at.1` is the pad's pose before
    /// the last step, the reading's pose when its image has none), then the object is perturbed.
    fn read_surface(
        &mut self,
        scene: &mut Scene,
        arm: &Arm,
        expansion: &Expansion<'_>,
        at: (usize, PadPose),
        record: &mut Record<'_>,
    ) -> Result<(), ControlError> {
        let (vertex, pad) = at;
        let lay = scene.object_pose().filter(|_| scene.object_is_free());
        let mut reading = self.settle_here(scene, arm, expansion)?;
        if let Some(lay) = lay {
            record.report.object_motions.push(scene.object_motion_from(&lay)?);
        }
        relabel_table_contact(&mut reading, &self.setup.sensor);
        let converged = reading.is_converged();
        let pose = reading.image.pose().copied().unwrap_or(pad);
        record.push(reading, scene);
        if converged {
            self.grid.add(pose.center_m);
            self.lift_off(scene, arm, vertex, &pose)?;
        }
        if let Some(motion) = self.setup.perturb(scene, &mut self.rng)? {
            record.report.perturbation_motions.push(motion);
        }
        Ok(())
    }

    /// Lifts the pad off the surface it read at `pose` along its normal by `lift_off_m`, and adds
    /// the configuration the arm reached to the tree as a child of `vertex`, so local expansions
    /// start facing the surface they read (nothing when no checked motion gets there).
    fn lift_off(
        &mut self,
        scene: &mut Scene,
        arm: &Arm,
        vertex: usize,
        pose: &PadPose,
    ) -> Result<(), ControlError> {
        let lifted = PadTarget {
            center_m: pose.center_m - pose.normal * self.config.lift_off_m,
            normal: pose.normal,
        };
        let start = arm.q(scene.data());
        if let Ok(q_lift) = self.expansion_ik.solve(&lifted, &start)
            && arm.move_to(scene, &q_lift, &self.expansion_motion, |_| false)? == MoveOutcome::Reached
        {
            let q = arm.q(scene.data());
            let pad = arm.pad_pose(scene.data());
            self.tree.add(vertex, q, pad.center_m, pad.normal);
        }
        Ok(())
    }

    /// One target by the paper's rule (Sec. III-A): local with probability L once a reading exists
    /// (a point near a reading of a sparsely read cell, kept in the workspace), else global (uniform
    /// in the workspace). `None` when the local draw found no cell.
    fn propose(&mut self) -> Option<(Strategy, DVec3)> {
        if !self.grid.is_empty() && self.rng.random_range(0.0..1.0) < self.config.local_probability {
            let p = self
                .grid
                .local_target(self.config.local_radius_m, &mut self.rng)?;
            // Targets stay in the workspace, above the table.
            return Some((
                Strategy::Local,
                p.clamp(self.config.workspace_min_m, self.config.workspace_max_m),
            ));
        }
        let (lo, hi) = (self.config.workspace_min_m, self.config.workspace_max_m);
        Some((
            Strategy::Global,
            DVec3::new(
                self.rng.random_range(lo.x..=hi.x),
                self.rng.random_range(lo.y..=hi.y),
                self.rng.random_range(lo.z..=hi.z),
            ),
        ))
    }

    /// One guarded expansion motion to `q`, watching the sensor: the motion's outcome and whether the
    /// sensor felt the object (a taxel above `threshold`), which stopped it.
    fn expand_to(
        &mut self,
        scene: &mut Scene,
        arm: &Arm,
        q: &[f64],
        threshold: f64,
    ) -> Result<(MoveOutcome, bool), ControlError> {
        let reader = &mut self.reader;
        let covering = self.covering.as_ref();
        let mut sensed = false;
        let mut read_error = None;
        let mut read = |s: &mut Scene| match reader(s) {
            Ok(image) => {
                sensed = image.max() > threshold;
                sensed
            }
            Err(e) => {
                read_error = Some(e);
                true
            }
        };
        // The object at the pad's rigid back as the sensor last saw it (a wall met side-on, a
        // blade between two samples): a collision of the motion, like MuJoCo's.
        let back_reached = |s: &Scene| {
            covering
                .is_some_and(|c| c.back_reached(s.model(), s.data()))
                .then(Collision::back_on_object)
        };
        let outcome = match self.expansion_motion.execution {
            Execution::Servo => arm.move_to(scene, q, &self.expansion_motion, read)?,
            Execution::Kinematic => {
                let reach_m = self.covering_reach_m;
                let fine_m = self.setup.control.approach_step_thickness * self.setup.sensor.thickness_m;
                let horizon_m = reach_m + self.expansion_motion.max_pad_step_m;
                arm.move_kinematic(scene, q, &self.expansion_motion, |s| {
                    if reach_m.is_finite()
                        && let Some(clearance_m) = arm.pad_clearance_m(s, horizon_m)?
                        && clearance_m > reach_m + fine_m
                    {
                        return Ok(Watch::Continue {
                            max_pad_step_m: clearance_m - reach_m,
                        });
                    }
                    let felt = read(s);
                    if let Some(contact) = back_reached(s) {
                        return Ok(Watch::Blocked(contact));
                    }
                    Ok(if felt {
                        Watch::Stop
                    } else {
                        Watch::Continue {
                            max_pad_step_m: fine_m,
                        }
                    })
                })?
            }
        };
        if let Some(e) = read_error {
            return Err(e);
        }
        Ok((outcome, sensed))
    }

    /// Hands over to surface contact control at the current pose and packages the outcome; a
    /// physics fault on the way restores `checkpoint` and gives an `aborted` reading.
    fn settle_here(
        &mut self,
        scene: &mut Scene,
        arm: &Arm,
        expansion: &Expansion<'_>,
    ) -> Result<Reading, ControlError> {
        let Expansion {
            object,
            label: strategy,
            checkpoint,
            guarded,
            ..
        } = *expansion;
        let object_pose = scene.object_pose().unwrap_or_default();
        let start = arm.pad_pose(scene.data());
        let Self {
            ik,
            reader,
            setup: TouchSetup { sensor, control, .. },
            motion,
            covering: _,
            ..
        } = self;
        let mut carrier = ArmPad::new(scene, ik, *sensor, |s: &mut Scene| reader(s), *motion)?;
        if guarded {
            carrier = carrier.limited_by_the_table();
        }
        match settle(&mut carrier, control) {
            Ok(outcome) => Ok(attempt_reading(outcome, object, object_pose, strategy)),
            Err(e) if e.is_physics_fault() => {
                scene.restore(checkpoint)?;
                Ok(aborted_reading(sensor, start, object, object_pose, strategy)?)
            }
            Err(e) => Err(e),
        }
    }
}

/// A converged reading whose covering meets the table ([`covering_meets_table`]) becomes a
/// `Collision` with the cause [`AttemptCause::CoveringOnTable`].
fn relabel_table_contact(reading: &mut Reading, sensor: &SensorConfig) {
    if reading.is_converged() && covering_meets_table(&reading.image, sensor) {
        reading.status = ContactStatus::Collision;
        reading.cause = Some(AttemptCause::CoveringOnTable);
    }
}

/// Whether the covering's volume (the pad rectangle swept `t` along the normal) reaches the table
/// top. The robot knows its table, as it knows the workspace box: a reading pressed on the table is
/// a reading of the environment, not of the unknown object, so the planner reports it as a
/// `Collision` (with the environment), keeps it out of the grid and out of recognition.
pub fn covering_meets_table(image: &TactileImage, sensor: &SensorConfig) -> bool {
    let Some(pose) = image.pose() else {
        return false;
    };
    let (half_w, half_h) = (0.5 * sensor.pad_width_m, 0.5 * sensor.pad_height_m);
    let lowest_z = [-1.0, 1.0]
        .into_iter()
        .flat_map(|a| [-1.0, 1.0].map(|b| pose.transform_point(DVec3::new(a * half_w, b * half_h, 0.0))))
        .flat_map(|corner| [corner, corner + pose.normal * sensor.thickness_m])
        .map(|p| p.z)
        .fold(f64::INFINITY, f64::min);
    lowest_z <= TABLE_TOP_Z_M + 1e-4
}

/// `from` turned toward `to` (both unit) by at most `max_rad`.
pub fn turn_toward(from: DVec3, to: DVec3, max_rad: f64) -> DVec3 {
    let angle = from.angle_between(to);
    if angle <= max_rad {
        return to;
    }
    let axis = from
        .cross(to)
        .try_normalize()
        .unwrap_or_else(|| from.any_orthonormal_vector());
    glam::DQuat::from_axis_angle(axis, max_rad) * from
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_iteration_budget_grows_with_the_readings_asked_for() {
        assert_eq!(PlannerConfig::iterations_for(10), 20_000);
        assert_eq!(PlannerConfig::iterations_for(100), 20_000);
        assert_eq!(PlannerConfig::iterations_for(1000), 200_000);
        assert_eq!(PlannerConfig::iterations_for(usize::MAX), usize::MAX);
    }

    #[test]
    fn every_numeric_field_is_checked_and_named() {
        assert_eq!(PlannerConfig::default().check(), Ok(()));
        // Each real field in turn negative, each count zero: the error must name that field.
        let defaults = serde_json::to_value(PlannerConfig::default()).unwrap();
        let fields = defaults.as_object().unwrap();
        let mut checked = 0;
        for (name, value) in fields {
            let out_of_range = if value.is_u64() {
                serde_json::json!(0)
            } else if value.is_f64() {
                serde_json::json!(-1.0)
            } else {
                continue;
            };
            let mut bad = fields.clone();
            bad.insert(name.clone(), out_of_range);
            let config: PlannerConfig = serde_json::from_value(serde_json::Value::Object(bad)).unwrap();
            assert_eq!(config.check().expect_err(name).field, name.as_str());
            checked += 1;
        }
        assert_eq!(checked, 8);
        let inverted = PlannerConfig {
            workspace_min_m: PlannerConfig::default().workspace_max_m,
            workspace_max_m: PlannerConfig::default().workspace_min_m,
            ..PlannerConfig::default()
        };
        assert_eq!(inverted.check().unwrap_err().field, "workspace_min_m");
        let nan_box = PlannerConfig {
            workspace_max_m: DVec3::new(f64::NAN, 0.1, 0.2),
            ..PlannerConfig::default()
        };
        assert_eq!(nan_box.check().unwrap_err().field, "workspace_min_m");
        let certain = PlannerConfig {
            local_probability: 1.5,
            ..PlannerConfig::default()
        };
        let error = Valid::new(certain).unwrap_err();
        assert_eq!(
            error.to_string(),
            "planner config: local_probability = 1.5 is outside [0, 1]"
        );
    }
}
