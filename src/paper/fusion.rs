//! Beyond the paper: where each touch landed. The product's recogniser weighs two kinds of
//! evidence (`recognize::geometric`): the tactile images' appearance (the bag of features of
//! Sec. IV, here MNTI and SIFT fused, the product's recipe) and the contacts (each converged
//! touch's point and normal against every object's known surface at a pose it is not told,
//! `locate`). This experiment measures each alone and their fusion on the arm's blind
//! explorations of the 3D set at L = 0.5 and L = 1 (Sec. III-A), the object fixed or perturbed
//! after every reading (Sec. V-B4), every object starting at a random pose (any heading, a tilt of
//! up to 10 degrees, a shift of up to 10% of its width; `sim::start_pose`), so that the contacts
//! cannot learn where the objects stand.
//!
//! The model is the product's: appearance trained on the end-to-end recipe's readings (three
//! times the scale's sampler readings per object, from the starts the arm can reach), the
//! contacts' weight and every posterior's tempering fitted on the arm's own explorations at random
//! start poses (L = 0.5 and 1 with the object fixed, L = 0.5 perturbed; a moving object's
//! evidence is weighed apart), never on a test exploration. Each curve recognises the same test
//! explorations with one kind of evidence (`evidence`), so the three are compared on the same
//! touches.
//!
//! The active curves (`strategy` = `active`) choose each touch with the fused model in the loop:
//! the planner's candidates scored by expected information gain (`active_touch`, the `active`
//! experiment's strategy and the demo's, its gain the appearance's), the belief updated after every
//! touch with both kinds of evidence. They cannot come from a dataset collected beforehand, so they
//! explore anew under the plans of the blind L = 0.5 test explorations (the same starts, sensor,
//! random streams and perturbations: common random numbers), as many converged touches as those.
//!
//! Besides the accuracy table, `fusion_attempts.csv` counts the same curves in touch attempts
//! ([`AttemptRow`]): a touch that met nothing, collided or did not settle costs a touch but gives
//! no reading.

use std::sync::Arc;

use serde::Serialize;

use super::active::{ACTIVE_LOCAL_PROBABILITY, explore_actively};
use super::context::{Family, PaperContext};
use super::data::{DataRequest, Objects};
use super::figures::{END_TO_END_TRAINING_FRACTION, default_sensor};
use super::recognition::{
    CALIBRATION_STREAM, CalibratedOn, Setting, SettingData, TEST_STREAM, training_config,
};
use super::scale::DataCounts;
use crate::active_touch::ActiveRecognition;
use crate::bodies::FreeBody;
use crate::dataset::{Dataset, Perturbed};
use crate::describe::DescriptorKind;
use crate::experiment::accuracy::{AccuracyCurve, AccuracyRow, AttemptRow, PerObjectRow, ReliabilityRow};
use crate::experiment::factor::{Factor, Factors};
use crate::experiment::layout::ExperimentDir;
use crate::experiment::name::SafeName;
use crate::experiment::plot::{Axis, PlotSpec};
use crate::experiment::progress::Progress;
use crate::experiment::runner::{Experiment, RunReport, run};
use crate::experiment::spec::ExperimentSpec;
use crate::experiment::unit::{BoxError, DetailRow, Unit};
use crate::explore::active::DEFAULT_CANDIDATES;
use crate::explore::collect::CollectPlan;
use crate::explore::{PlannerConfig, SamplerConfig};
use crate::locate::{ContactNoise, GeometryModel, GeometryParams};
use crate::mesh::TriMesh;
use crate::pose::StartPose;
use crate::recognize::{
    Appearance, CodebookKind, DescriptorChoice, Evidence, FusedModel, GeometricFusion, PosteriorRule,
    ReadingRange, Recognizer, ReliabilityTable, TouchReading, TrainConfig, Trial,
};
use crate::sim::PerturbationBounds;

pub const EXPERIMENT_NAME: &str = "fusion";
pub const DESCRIPTION: &str = "Beyond the paper: appearance, contact geometry and their fusion (MNTI+SIFT; 3D set at random start poses, blind L = 0.5 and 1 and the fused model's active touch, fixed and perturbed), against readings and touch attempts";

/// The appearance descriptors: the product's recipe (`taction train --descriptor mnti+sift`).
const DESCRIPTORS: [DescriptorKind; 2] = [DescriptorKind::Mnti, DescriptorKind::Sift];

/// The evidence each curve weighs, in the order of the legend.
const EVIDENCE: [Evidence; 3] = [Evidence::Appearance, Evidence::Contacts, Evidence::Fused];

/// The blind strategies explored (L).
const LOCAL_PROBABILITIES: [f64; 2] = [0.5, 1.0];

/// L of the perturbed calibration explorations, which weigh a moving object's evidence.
const MOVING_CALIBRATION_L: f64 = 0.5;

/// The legend's name of a curve.
const CURVE_LABEL: &str = "{evidence} {strategy} L={local_probability} {object_motion}";

/// The `strategy` level of the planner's random local or global moves.
const BLIND: &str = "blind";

/// The `strategy` level of the planner's candidates scored by expected information gain, the
/// fused model in the loop (`active_touch`).
const ACTIVE: &str = "active";

/// A curve's levels: the `evidence` weighed, the `strategy` that chose the touches, L =
/// `local_probability` (of the active strategy's proposals), the object `motion`.
fn levels(evidence: Evidence, strategy: &str, local_probability: f64, motion: &str) -> Factors {
    Factors::new([
        (Factor::Evidence, evidence.name().to_string()),
        (Factor::Strategy, strategy.to_string()),
        (Factor::LocalProbability, local_probability.to_string()),
        (Factor::ObjectMotion, motion.to_string()),
    ])
}

fn object_states() -> [(&'static str, PerturbationBounds); 2] {
    [
        ("fixed", PerturbationBounds::NONE),
        ("perturbed", PerturbationBounds::PAPER),
    ]
}

/// The training data's setting: the end-to-end recipe's (`paper::figures::end_to_end`,
/// "reachable"). Its appearance models are calibrated on their validation readings only because
/// the fusion fits its own temperings on the arm's explorations ([`FusionData::calibration`]).
pub(super) fn setting() -> Setting {
    Setting {
        label: EXPERIMENT_NAME.into(),
        sensor: default_sensor(),
        sampler: SamplerConfig {
            reachable_by_arm: true,
            ..SamplerConfig::default()
        },
        training_fraction: END_TO_END_TRAINING_FRACTION,
        calibrated_on: CalibratedOn::Validation,
        curves: Vec::new(),
    }
}

/// What the calibration explorations are, as `config.json` records them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
struct FusionCalibration {
    /// L of the explorations with the object fixed.
    fixed_local_probabilities: [f64; 2],
    /// L of the explorations with the object perturbed after every reading.
    perturbed_local_probability: f64,
    /// Explorations of each object at each of them, each on a random stream of its own.
    explorations: usize,
    readings_per_object: usize,
    /// Readings per calibration trial: a test run's.
    trial_readings: usize,
}

/// How the active curves explore, as `config.json` records them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
struct FusionActive {
    /// L of the active strategy's proposals, and of the blind test explorations whose plans
    /// (starts, sensor, random streams, perturbations) the active ones share.
    local_probability: f64,
    candidates: usize,
    /// Readings nearer than this to a candidate discount its appearance gain (`active_touch`).
    neighbourhood_m: f64,
    /// What the gain scores: a touch's `appearance` (the product's default, `taction demo
    /// --gain`); the belief it starts from is the fused one.
    gain: &'static str,
}

impl FusionActive {
    fn new() -> Self {
        Self {
            local_probability: ACTIVE_LOCAL_PROBABILITY,
            candidates: DEFAULT_CANDIDATES,
            neighbourhood_m: PlannerConfig::default().grid_cell_m,
            gain: "appearance",
        }
    }
}

/// Everything the rows depend on, written as the run's `config.json`.
#[derive(Serialize)]
struct FusionConfig<'a> {
    setting: &'a Setting,
    descriptor: String,
    evidence: Vec<&'static str>,
    local_probabilities: [f64; 2],
    active: FusionActive,
    start_pose: StartPose,
    geometry: GeometryParams,
    contact_noise: ContactNoise,
    calibration: FusionCalibration,
    posterior: PosteriorRule,
    scale: f64,
    counts: DataCounts,
    seed: u64,
    object_set_id: String,
    objects: Vec<String>,
    training: TrainConfig,
}

/// The test explorations of one (L, motion), one per repetition.
type TestExplorations = (f64, &'static str, Vec<DataRequest>);

/// The unit's rows: accuracy, and the per-object, reliability and attempt rows.
pub(super) type Rows = (
    Vec<AccuracyRow>,
    (Vec<PerObjectRow>, Vec<ReliabilityRow>, Vec<AttemptRow>),
);

/// What the product's fused model is made of in a run: the `fusion` setting on the 3D set, its
/// data counts and training, the explorations' random start poses (`free-object` shares it).
pub(super) struct FusionBasis {
    pub setting: Setting,
    pub objects: Arc<Objects>,
    pub counts: DataCounts,
    pub training: TrainConfig,
    pub start_pose: StartPose,
}

impl FusionBasis {
    pub(super) fn of(context: &PaperContext, codebook: CodebookKind) -> Result<Self, BoxError> {
        let setting = setting();
        let objects = context.objects(Family::Shapes)?;
        let counts = setting.counts(context.scale.counts());
        let training = training_config(context, codebook, counts, objects.specs.len());
        let start_pose = StartPose::Random {
            max_heading: objects.set.start_heading(),
        };
        Ok(Self {
            setting,
            objects,
            counts,
            training,
            start_pose,
        })
    }

    /// The unit of `experiment` that judges explorations with the model in `context`.
    pub(super) fn unit<'a>(&'a self, context: &'a PaperContext, experiment: &'static str) -> FusionUnit<'a> {
        FusionUnit {
            experiment,
            data: SettingData::new(context, &self.objects, &self.setting, self.counts),
            objects: Arc::clone(&self.objects),
            training: self.training.clone(),
            start_pose: self.start_pose,
        }
    }
}

/// The plot of `experiment`'s accuracy against touch attempts (its `attempts` table), its curves
/// told apart by the `factors` columns and named by `legend`.
pub(super) fn attempts_plot(
    experiment: &str,
    title: &str,
    factors: &[&str],
    legend: &str,
) -> Result<PlotSpec, BoxError> {
    let mut plot = PlotSpec::lines(
        SafeName::new(format!("{experiment}-attempts"))?,
        title,
        Axis::new("n_attempts", "touch attempts per object"),
        vec![Axis::new("accuracy", "accuracy")],
        factors,
    )
    .with_legend(legend);
    plot.table = AttemptRow::TABLE.map(SafeName::new).transpose()?;
    Ok(plot)
}

/// Runs the experiment in `context` (one unit: the model, then every curve).
pub fn run_fusion(context: &PaperContext, codebook: CodebookKind) -> Result<RunReport, BoxError> {
    let basis = FusionBasis::of(context, codebook)?;
    let FusionBasis {
        setting,
        objects,
        counts,
        training,
        start_pose,
    } = &basis;
    let name = SafeName::new(EXPERIMENT_NAME)?;
    let choice = DescriptorChoice::fused(DESCRIPTORS.to_vec())?;
    let key = SafeName::builder(choice.name()).build()?;
    let dir = ExperimentDir::new(&context.options.out, &name);
    let work = basis.unit(context, EXPERIMENT_NAME);
    if context.options.shard.contains(0) && !dir.unit_csv(&key).exists() {
        context.store.prepare(&work.requests()?, dir.root())?;
    }
    let config = FusionConfig {
        setting,
        descriptor: choice.name(),
        evidence: EVIDENCE.iter().map(Evidence::name).collect(),
        local_probabilities: LOCAL_PROBABILITIES,
        active: FusionActive::new(),
        start_pose: *start_pose,
        geometry: GeometryParams {
            max_heading: objects.set.start_heading(),
            ..GeometryParams::default()
        },
        contact_noise: ContactNoise::default(),
        calibration: work.calibration_record(),
        posterior: context.posterior(),
        scale: context.scale.fraction(),
        counts: *counts,
        seed: context.seed,
        object_set_id: objects.set.id(),
        objects: objects.names(),
        training: training.clone(),
    };
    let title = "Appearance, contact geometry and their fusion (random start poses)";
    let plot = PlotSpec::accuracy(name.clone(), title)
        .with_chance(objects.specs.len())
        .with_legend(CURVE_LABEL);
    let attempts = attempts_plot(
        EXPERIMENT_NAME,
        "Accuracy against touch attempts (converged or not)",
        &["evidence", "strategy", "local_probability", "object_motion"],
        CURVE_LABEL,
    )?;
    let experiment = Experiment {
        spec: ExperimentSpec {
            name: name.clone(),
            description: DESCRIPTION.to_string(),
            plots: vec![
                plot,
                PlotSpec::reliability(
                    SafeName::new(format!("{EXPERIMENT_NAME}-reliability"))?,
                    &format!("Calibration: {title}"),
                )?
                .with_legend(CURVE_LABEL),
                attempts,
            ],
        },
        config,
        units: vec![
            Unit::<_, (PerObjectRow, ReliabilityRow, AttemptRow)>::with_detail(key, move || work.rows()),
        ],
    };
    Ok(run(&experiment, &context.options)?)
}

/// What the experiment's one unit works from: the product's fused model and the arm's
/// explorations it judges (the `free-object` experiment's too).
pub(super) struct FusionUnit<'a> {
    /// The experiment whose rows it writes.
    pub experiment: &'static str,
    pub data: SettingData<'a>,
    pub objects: Arc<Objects>,
    pub training: TrainConfig,
    pub start_pose: StartPose,
}

impl FusionUnit<'_> {
    /// The explorations at `l`, the object held and moved as `object` says (a mocap body when
    /// its body is `None`), one per trial, `readings` per object, from `first_stream`.
    pub(super) fn explorations(
        &self,
        l: f64,
        object: (PerturbationBounds, Option<FreeBody>),
        readings: usize,
        first_stream: u64,
    ) -> Result<Vec<DataRequest>, BoxError> {
        Ok(self
            .data
            .planner_trials(l, object, self.start_pose, readings, first_stream)?)
    }

    /// The arm's explorations the fusion is weighed on: at each L of [`LOCAL_PROBABILITIES`] with
    /// the object fixed, and at [`MOVING_CALIBRATION_L`] perturbed, each on streams of its own
    /// (those of the arm calibration of the other experiments, whose explorations start at the
    /// canonical pose and so are other datasets, and past them for the perturbed ones).
    fn calibration(&self) -> Result<Vec<DataRequest>, BoxError> {
        let readings = self.data.counts.validation_per_object;
        let mut requests = Vec::new();
        for (i, l) in LOCAL_PROBABILITIES.into_iter().enumerate() {
            requests.extend(self.explorations(
                l,
                (PerturbationBounds::NONE, None),
                readings,
                CALIBRATION_STREAM + 100 * i as u64,
            )?);
        }
        let moving = CALIBRATION_STREAM + 100 * LOCAL_PROBABILITIES.len() as u64;
        requests.extend(self.explorations(
            MOVING_CALIBRATION_L,
            (PerturbationBounds::PAPER, None),
            readings,
            moving,
        )?);
        Ok(requests)
    }

    fn calibration_record(&self) -> FusionCalibration {
        FusionCalibration {
            fixed_local_probabilities: LOCAL_PROBABILITIES,
            perturbed_local_probability: MOVING_CALIBRATION_L,
            explorations: self.data.counts.trials,
            readings_per_object: self.data.counts.validation_per_object,
            trial_readings: self.data.counts.test_per_object,
        }
    }

    /// The test explorations of each (L, motion): L = 0.5 then 1, each fixed then perturbed.
    fn tests(&self) -> Result<Vec<TestExplorations>, BoxError> {
        let mut tests = Vec::new();
        for l in LOCAL_PROBABILITIES {
            for (motion, perturbation) in object_states() {
                let requests = self.explorations(
                    l,
                    (perturbation, None),
                    self.data.counts.test_per_object,
                    TEST_STREAM,
                )?;
                tests.push((l, motion, requests));
            }
        }
        Ok(tests)
    }

    /// Every dataset the model is made of: training, validation and calibration.
    pub(super) fn model_requests(&self) -> Result<Vec<DataRequest>, BoxError> {
        let mut requests = vec![self.data.training_request()?, self.data.validation_request()?];
        requests.extend(self.calibration()?);
        Ok(requests)
    }

    /// Every dataset the unit reads.
    fn requests(&self) -> Result<Vec<DataRequest>, BoxError> {
        let mut requests = self.model_requests()?;
        for (.., tests) in self.tests()? {
            requests.extend(tests);
        }
        Ok(requests)
    }

    /// The product's model: MNTI and SIFT fused (each trained and chosen as every figure's model,
    /// the fusion's tempering fitted on the validation readings), then fused with the contact
    /// geometry of every object's mesh, weighed on the arm's explorations.
    pub(super) fn model(&self) -> Result<GeometricFusion, BoxError> {
        let store = &self.data.context.store;
        let (training, validation) = (self.data.training_request()?, self.data.validation_request()?);
        let parts = DESCRIPTORS
            .iter()
            .map(|kind| store.model(&training, &validation, kind.build().as_ref(), &self.training))
            .collect::<Result<Vec<_>, _>>()?;
        let (training_data, validation_data) = (store.dataset(&training)?, store.dataset(&validation)?);
        let appearance =
            FusedModel::new(parts)?.calibrated(&self.training, &training_data, Some(&validation_data))?;
        let meshes: Vec<(String, &TriMesh)> = self
            .objects
            .specs
            .iter()
            .map(|o| (o.name.clone(), &o.mesh))
            .collect();
        let geometry =
            GeometryModel::of_named(appearance.objects(), &meshes, self.objects.set.start_heading())?;
        let calibration = self
            .calibration()?
            .iter()
            .map(|request| store.dataset(request))
            .collect::<Result<Vec<_>, _>>()?;
        let calibration: Vec<&Dataset> = calibration.iter().map(AsRef::as_ref).collect();
        let model = store.clock.training(|| {
            GeometricFusion::new(Appearance::Fused(Box::new(appearance)), geometry)?
                .calibrate_on_all(&calibration, self.data.counts.test_per_object)
        })?;
        Ok(model.with_posterior(self.data.context.posterior()))
    }

    /// The model, then each (L, motion)'s test explorations, described once, recognised with each
    /// evidence; then the active curves, on the plans of the L = 0.5 explorations.
    fn rows(&self) -> Result<Rows, BoxError> {
        let model = self.model()?;
        let mut rows: Rows = Default::default();
        let mut active_plans = Vec::new();
        for (l, motion, requests) in self.tests()? {
            let tests = self.test_runs(&model, &requests)?;
            for evidence in EVIDENCE {
                let judge = model.clone().with_evidence(evidence);
                extend(
                    &mut rows,
                    self.curve_rows(&judge, &levels(evidence, BLIND, l, motion), &tests)?,
                );
            }
            if l == ACTIVE_LOCAL_PROBABILITY {
                let plans = requests.iter().zip(&tests).map(|(r, t)| (r.plan, t.motion));
                active_plans.push((motion, plans.collect::<Vec<_>>()));
            }
        }
        let fused = model.with_evidence(Evidence::Fused);
        for (motion, tests) in self.active_tests(&fused, &active_plans)? {
            let factors = levels(Evidence::Fused, ACTIVE, ACTIVE_LOCAL_PROBABILITY, motion);
            extend(&mut rows, self.curve_rows(&fused, &factors, &tests)?);
        }
        Ok(rows)
    }

    /// The active curves' explorations: for each motion's `plans` (those of its blind test
    /// explorations, one per trial), every object explored actively with `model` in the loop,
    /// as many converged touches as a blind test run. All of them share one pass over the pool
    /// ([`crate::queue`]), the perturbed ones (the longer) first, as the `active` experiment's.
    fn active_tests<'m>(
        &self,
        model: &GeometricFusion,
        plans: &[(&'m str, Vec<(CollectPlan, Perturbed)>)],
    ) -> Result<Vec<(&'m str, Vec<TestRun>)>, BoxError> {
        let objects = &self.objects;
        let recognizer = Recognizer::Geometric(Box::new(model.clone()));
        let descriptors = model.descriptors()?;
        let active = FusionActive::new();
        let jobs: Vec<(usize, usize, usize)> = (0..plans.len())
            .rev()
            .flat_map(|s| {
                (0..plans[s].1.len()).flat_map(move |t| (0..objects.specs.len()).map(move |o| (s, t, o)))
            })
            .collect();
        // The curves are part of the run's one unit, saved when whole: the bar says how far.
        let progress = Progress::new("active touch (fused)", jobs.len(), "objects explored");
        let explored = crate::queue::run_in_order(jobs.len(), |i| -> Result<_, BoxError> {
            let (s, t, o) = jobs[i];
            let (plan, motion) = &plans[s].1[t];
            let name = &objects.specs[o].name;
            let object = model
                .objects()
                .iter()
                .position(|n| n == name)
                .ok_or_else(|| format!("object '{name}' is not in the fused model"))?;
            let mut recognition = ActiveRecognition::of(&recognizer, active.neighbourhood_m, *motion)?;
            let run = explore_actively(
                plan,
                objects,
                o,
                &mut recognition,
                self.data.counts.test_per_object,
            )?;
            let readings = run
                .touches
                .iter()
                .map(|t| model.touch_reading(&descriptors, &t.reading.image, t.attempt))
                .collect();
            let mut converged = vec![false; run.attempts];
            for touch in &run.touches {
                converged[touch.attempt] = true;
            }
            progress.inc();
            Ok((Trial { object, readings }, converged))
        })?;
        progress.finish(explored.len());
        let mut explored = jobs.iter().zip(explored);
        let mut curves: Vec<(&str, Vec<TestRun>)> = Vec::new();
        for (motion, motion_plans) in plans.iter().rev() {
            let mut tests = Vec::new();
            for (plan, perturbed) in motion_plans {
                let (trials, attempts) = explored
                    .by_ref()
                    .take(objects.specs.len())
                    .map(|(_, e)| e)
                    .unzip();
                tests.push(TestRun {
                    stream_seed: plan.seed,
                    motion: *perturbed,
                    trials,
                    attempts,
                });
            }
            curves.push((motion, tests));
        }
        curves.reverse();
        Ok(curves)
    }

    /// The test explorations of `requests`, each described by `model` (the readings of each
    /// object one sequence) with every object's attempts.
    pub(super) fn test_runs(
        &self,
        model: &GeometricFusion,
        requests: &[DataRequest],
    ) -> Result<Vec<TestRun>, BoxError> {
        let mut tests = Vec::new();
        for request in requests {
            let test = self.data.context.store.dataset(request)?;
            let trials = model.trials(&test, usize::MAX)?;
            let attempts = attempt_logs(model.objects(), &test, &trials)?;
            tests.push(TestRun {
                stream_seed: request.plan.seed,
                motion: test.header().perturbation,
                trials,
                attempts,
            });
        }
        Ok(tests)
    }

    /// One curve: `model` recognising each test exploration (one repetition per dataset, each
    /// object's readings one sequence) at every reading count and every attempt count.
    pub(super) fn curve_rows(
        &self,
        model: &GeometricFusion,
        factors: &Factors,
        tests: &[TestRun],
    ) -> Result<Rows, BoxError> {
        let mut rows: Rows = Default::default();
        let mut table = ReliabilityTable::default();
        let mut meta = AccuracyCurve {
            experiment: self.experiment.to_string(),
            descriptor: model.appearance().choice().name(),
            factors: factors.clone(),
            trial: 0,
            seed: self.data.context.seed,
            stream_seed: 0,
        };
        let last = tests
            .iter()
            .flat_map(|t| &t.attempts)
            .map(Vec::len)
            .max()
            .unwrap_or(0);
        for (trial, test) in tests.iter().enumerate() {
            (meta.trial, meta.stream_seed) = (trial as u32, test.stream_seed);
            let longest = test.trials.iter().map(|t| t.readings.len()).max().unwrap_or(0);
            if longest == 0 {
                return Err(format!(
                    "curve '{factors}', trial {trial}: no converged test reading of any object"
                )
                .into());
            }
            let evaluation = model.evaluate(&test.trials, ReadingRange::new(1, longest)?, test.motion)?;
            rows.0.extend(meta.rows(&evaluation.accuracy));
            rows.1.0.extend(meta.object_rows(&evaluation)?);
            rows.1
                .2
                .extend(meta.attempt_rows(&evaluation, &test.attempts, last)?);
            table.merge(&evaluation.reliability());
        }
        rows.1.1 = meta.reliability_rows(&table);
        Ok(rows)
    }
}

/// Appends one curve's rows to the unit's.
pub(super) fn extend(rows: &mut Rows, (accuracy, (per_object, reliability, attempts)): Rows) {
    rows.0.extend(accuracy);
    rows.1.0.extend(per_object);
    rows.1.1.extend(reliability);
    rows.1.2.extend(attempts);
}

/// One test exploration, described: each object's readings with their touches, and each object's
/// attempts (whether each converged), in the same order.
pub(super) struct TestRun {
    stream_seed: u64,
    motion: Perturbed,
    trials: Vec<Trial<TouchReading>>,
    attempts: Vec<Vec<bool>>,
}

/// Each of `trials`' object's attempts in `test` (names: the model's objects): whether each
/// converged.
fn attempt_logs(
    names: &[String],
    test: &Dataset,
    trials: &[Trial<TouchReading>],
) -> Result<Vec<Vec<bool>>, BoxError> {
    let by_object = test.by_object();
    trials
        .iter()
        .map(|t| {
            let name = &names[t.object];
            let j = test
                .header()
                .object_index(name)
                .ok_or_else(|| format!("object '{name}' is not in the test data"))?;
            Ok(by_object[j].iter().map(|r| r.is_converged()).collect())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_curve_has_the_same_factor_columns_and_a_level_of_each() {
        let mut curves = Vec::new();
        for (motion, _) in object_states() {
            for evidence in EVIDENCE {
                for l in LOCAL_PROBABILITIES {
                    curves.push(levels(evidence, BLIND, l, motion));
                }
            }
            curves.push(levels(Evidence::Fused, ACTIVE, ACTIVE_LOCAL_PROBABILITY, motion));
        }
        let mut names = std::collections::BTreeSet::new();
        for factors in &curves {
            factors.check().unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(
                factors.factors().collect::<Vec<_>>(),
                [
                    Factor::Evidence,
                    Factor::Strategy,
                    Factor::LocalProbability,
                    Factor::ObjectMotion
                ]
            );
            names.insert(factors.to_string());
        }
        assert_eq!(names.len(), 14, "fourteen distinct curves");
    }
}
