//! The shape every recognition figure of Sec. V shares (Figs. 7-13, 16a, 17): train a
//! bag-of-features model per (setting, descriptor) on sampler readings, then recognise test
//! readings touch by touch and record accuracy and reliability against the number of readings.
//!
//! A [`RecognitionSweep`] lists the settings a figure varies (sensor, training sampler) and, for
//! each, the curves it draws (which test data: validation readings, fresh sampler readings, the
//! planner's exploration, recorded real frames). One unit per (setting, descriptor): it trains or
//! loads the model and evaluates every curve of the setting over all trials, so units never share
//! a model within one experiment.

use std::sync::Arc;

use rand::seq::SliceRandom;
use serde::Serialize;

use super::context::{Family, PaperContext};
use super::data::{DataRequest, Objects};
use super::scale::DataCounts;
use crate::bodies::FreeBody;
use crate::control::ControlConfig;
use crate::dataset::recorded::{RealData, TaxelPitch, recorded_sensor};
use crate::describe::{Descriptor, DescriptorKind};
use crate::experiment::accuracy::{AccuracyCurve, AccuracyRow, PerObjectRow, ReliabilityRow};
use crate::experiment::factor::Factors;
use crate::experiment::layout::ExperimentDir;
use crate::experiment::name::SafeName;
use crate::experiment::plot::PlotSpec;
use crate::experiment::runner::{Experiment, RunReport, check_resumable, run};
use crate::experiment::spec::ExperimentSpec;
use crate::experiment::unit::{BoxError, Unit};
use crate::explore::collect::{CollectMode, CollectPlan};
use crate::explore::{PlannerConfig, SamplerConfig};
use crate::paper::sim_to_real::SimToRealPreprocess;
use crate::recognize::{
    CodebookKind, LabelledFeatures, PosteriorRule, ReadingRange, ReliabilityTable, TrainConfig, TrainedModel,
    Trial, evaluate, make_trials,
};
use crate::rng;
use crate::sim::{PerturbationBounds, StartPose};
use crate::tactile::SensorConfig;
use crate::valid::{RangeError, Valid};

/// Streams of the experiment seed (see [`crate::rng::substream`]); the same for every setting, so
/// settings are compared on the same random draws where they can be (common random numbers).
const TRAINING_STREAM: u64 = 1;
const VALIDATION_STREAM: u64 = 2;
const MODEL_STREAM: u64 = 3;
const NOISE_STREAM: u64 = 4;
const ORDERING_STREAM: u64 = 5;
/// Test trial `t` draws from stream `TEST_STREAM + t`.
pub(super) const TEST_STREAM: u64 = 100;
/// Calibration exploration `t` at the `i`-th of [`CALIBRATION_LOCAL_PROBABILITIES`] draws from
/// stream `CALIBRATION_STREAM + 100 i + t`.
pub(super) const CALIBRATION_STREAM: u64 = 200;

/// The blind strategies (local probability L) whose explorations calibrate a posterior that will
/// judge the arm's touches ([`SettingData::calibration_requests`]).
pub(super) const CALIBRATION_LOCAL_PROBABILITIES: [f64; 2] = [0.5, 1.0];

/// Which test readings a curve recognises.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum TestData {
    /// The validation readings the model was chosen on (Fig. 9): one trial.
    Validation,
    /// Fresh readings of the training sampler, one dataset per trial (the letters, Sec. V-D).
    Sampler,
    /// The planner exploring each object blind with the arm (Sec. III-A), one dataset per trial,
    /// the object perturbed after every reading within `perturbation` (Sec. V-B4).
    Planner {
        local_probability: f64,
        perturbation: PerturbationBounds,
    },
    /// The recorded real frames of the context (Sec. V-F), square-rooted and blurred; trial 0
    /// presents them in file order (Fig. 17b), the others in seeded random orders (Fig. 17a).
    Real,
}

/// One line of a figure: its levels of the figure's factors (its columns in the rows) and its test
/// data.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Curve {
    pub factors: Factors,
    pub test: TestData,
}

/// What the calibrated posterior (`recognize::calibration`) of a setting's models is fitted on.
/// Under the paper's Eq. 15 (`--posterior eq15`) nothing is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CalibratedOn {
    /// The sampler's validation readings the model was chosen on (training fits it): Fig. 9,
    /// which judges those readings, and the figures on other sensors than the default (Figs.
    /// 11-13), which would each need explorations of their own (`paper::figures`).
    Validation,
    /// The arm's own explorations ([`SettingData::calibration_requests`]), the kind of data the
    /// curves judge: the product's recipe for recognising the arm's touches. Fitted on the
    /// sampler's validation readings, the end-to-end models' posteriors were overconfident on the
    /// arm's touches, ECE 0.10-0.12 with our training over four seeds; fitted on the arm's
    /// explorations, 0.014-0.022 (docs/measurements.md, "End to end, calibrated on the arm").
    ArmExplorations,
}

impl CalibratedOn {
    fn is_validation(&self) -> bool {
        *self == Self::Validation
    }
}

/// The arm's explorations a run's posteriors were calibrated on, as its `config.json` records
/// them ([`CalibratedOn::ArmExplorations`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub(super) struct ArmCalibration {
    /// The blind strategies explored (local probability L), the object fixed.
    local_probabilities: [f64; 2],
    /// Explorations of each object at each L, each on a random stream of its own.
    explorations: usize,
    readings_per_object: usize,
    /// Readings per calibration trial: a test run's.
    trial_readings: usize,
}

impl ArmCalibration {
    /// The calibration of a run with data `counts` (the explorations of
    /// [`SettingData::calibration_requests`]).
    fn of(counts: DataCounts) -> Self {
        Self {
            local_probabilities: CALIBRATION_LOCAL_PROBABILITIES,
            explorations: counts.trials,
            readings_per_object: counts.validation_per_object,
            trial_readings: counts.test_per_object,
        }
    }
}

/// One trained model per descriptor: the sensor and training sampler, and the curves drawn with
/// that model.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Setting {
    /// Names the setting in unit keys (its curve's level when it has one).
    pub label: String,
    pub sensor: SensorConfig,
    pub sampler: SamplerConfig,
    /// Multiple of the scale's training readings per object this setting trains on (1 in the paper's
    /// figures; the training-size experiment varies it).
    pub training_fraction: f64,
    /// Written only when it is not the paper figures' validation readings.
    #[serde(skip_serializing_if = "CalibratedOn::is_validation")]
    pub calibrated_on: CalibratedOn,
    pub curves: Vec<Curve>,
}

impl Setting {
    /// A setting named `label` drawing one curve at `factors`.
    pub fn single(
        label: impl Into<String>,
        factors: Factors,
        sensor: SensorConfig,
        sampler: SamplerConfig,
        test: TestData,
    ) -> Self {
        Self {
            label: label.into(),
            sensor,
            sampler,
            training_fraction: 1.0,
            calibrated_on: CalibratedOn::Validation,
            curves: vec![Curve { factors, test }],
        }
    }
}

/// A recognition figure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecognitionSweep {
    pub name: &'static str,
    #[serde(skip)]
    pub description: &'static str,
    /// The plot's title; a sweep on recorded frames ends it with what they are
    /// ([`RealData::frames_words`]).
    #[serde(skip)]
    pub title: &'static str,
    /// The name settings' labels take in unit keys (`noise_fraction=0.1`); empty when the keys name
    /// only the descriptor. Keys only: the rows' columns are the curves' [`Factors`].
    #[serde(skip)]
    pub key_parameter: &'static str,
    /// How the plot's legend names a curve ([`PlotSpec::legend`]); `None`: `factor = level`.
    #[serde(skip)]
    pub legend: Option<&'static str>,
    pub family: Family,
    pub descriptors: Vec<DescriptorKind>,
    pub settings: Vec<Setting>,
}

/// Everything the rows depend on, written as the run's `config.json`.
#[derive(Serialize)]
struct SweepConfig<'a> {
    sweep: &'a RecognitionSweep,
    scale: f64,
    counts: DataCounts,
    seed: u64,
    object_set: String,
    object_set_id: String,
    objects: Vec<String>,
    control: ControlConfig,
    planner: PlannerConfig,
    training: TrainConfig,
    /// Present when a setting's posteriors are calibrated on the arm's explorations.
    #[serde(skip_serializing_if = "Option::is_none")]
    arm_calibration: Option<ArmCalibration>,
}

/// One unit's work, before it is wrapped in a closure.
struct UnitPlan<'a> {
    key: SafeName,
    setting: &'a Setting,
    descriptor: DescriptorKind,
}

/// Prepares the datasets of the units of `plans` that this shard runs and that have no rows yet.
fn prepare_pending(
    context: &PaperContext,
    objects: &Arc<Objects>,
    counts: DataCounts,
    plans: &[UnitPlan],
    dir: &ExperimentDir,
) -> Result<(), BoxError> {
    let mut requests = Vec::new();
    for (i, plan) in plans.iter().enumerate() {
        if context.options.shard.contains(i) && !dir.unit_csv(&plan.key).exists() {
            let setting_counts = plan.setting.counts(counts);
            requests.extend(SettingData::new(context, objects, plan.setting, setting_counts).requests()?);
        }
    }
    context.store.prepare(&requests, dir.root())?;
    Ok(())
}

impl RecognitionSweep {
    /// What its `config.json` records of the arm's explorations its posteriors are calibrated on
    /// in `context` with data `counts`: `None` when no setting's are
    /// ([`Setting::calibrated_on_arm`]).
    pub(super) fn arm_calibration(
        &self,
        context: &PaperContext,
        counts: DataCounts,
    ) -> Option<ArmCalibration> {
        self.settings
            .iter()
            .any(|setting| setting.calibrated_on_arm(context))
            .then(|| ArmCalibration::of(counts))
    }

    /// This sweep with every simulated sensor fitted to the recording `real` (Fig. 17 tests on
    /// it): unchanged without a `taxel_pitch` (the recording's grid must then be the sensor's, the
    /// paper's 6x6); with one, a pad of the recording's grid at that pitch
    /// ([`recorded_sensor`]), its covering the same share of the pad's shorter side and its noise
    /// the same as the figure's, so that the model learns frames the size and shape of those it
    /// is tested on.
    fn fitted_to(&self, real: &RealData, taxel_pitch: Option<TaxelPitch>) -> Result<Self, BoxError> {
        let mut sweep = self.clone();
        for setting in &mut sweep.settings {
            setting.sensor = match taxel_pitch {
                Some(pitch) => sensor_of_recording(&setting.sensor, real, pitch),
                None if (setting.sensor.rows, setting.sensor.cols) == (real.rows, real.cols) => {
                    setting.sensor
                }
                None => {
                    return Err(format!(
                        "--real: the frames are {}x{} taxels but the simulated sensor is {}x{}: give the \
                         recording's --taxel-pitch-m, and the simulated pad follows its grid",
                        real.rows, real.cols, setting.sensor.rows, setting.sensor.cols
                    )
                    .into());
                }
            };
        }
        Ok(sweep)
    }

    /// The plot's title: [`title`](Self::title), followed, when the sweep tests on recorded frames,
    /// by what they are (real sensor frames, or the synthetic example's).
    pub(crate) fn plot_title(&self, real: Option<&RealData>) -> String {
        match real {
            Some(real) => format!("{} {}", self.title, real.frames_words()),
            None => self.title.to_string(),
        }
    }

    /// Runs the sweep in `context`, every model with `codebook`: prepares the datasets its pending
    /// units need, then runs the units on the experiment framework (resumable, sharded, parallel).
    pub fn run(&self, context: &PaperContext, codebook: CodebookKind) -> Result<RunReport, BoxError> {
        let objects = context.objects(self.family)?;
        // The recorded frames are read, and the simulated sensor fitted to their grid, before any
        // dataset is collected.
        match self.family {
            Family::RealLabels => {
                let real = context.real_data()?;
                self.fitted_to(&real, context.real.taxel_pitch)?.run_with(
                    context,
                    codebook,
                    objects,
                    Some(real),
                )
            }
            _ => self.run_with(context, codebook, objects, None),
        }
    }

    /// [`run`](Self::run) on `objects`, and on the recorded frames `real` when the sweep tests on
    /// them.
    fn run_with(
        &self,
        context: &PaperContext,
        codebook: CodebookKind,
        objects: Arc<Objects>,
        real: Option<Arc<RealData>>,
    ) -> Result<RunReport, BoxError> {
        let counts = context.scale.counts();
        let plans = self.unit_plans()?;
        let name = SafeName::new(self.name)?;
        let config = SweepConfig {
            sweep: self,
            scale: context.scale.fraction(),
            counts,
            seed: context.seed,
            object_set: objects.set.name.clone(),
            object_set_id: objects.set.id(),
            objects: objects.names(),
            control: ControlConfig::default(),
            planner: PlannerConfig::default(),
            training: training_config(context, codebook, counts, objects.specs.len()),
            arm_calibration: self.arm_calibration(context, counts),
        };
        check_resumable(&context.options, &name, &config)?;
        let dir = ExperimentDir::new(&context.options.out, &name);
        prepare_pending(context, &objects, counts, &plans, &dir)?;
        let experiment = Experiment {
            spec: ExperimentSpec {
                name: name.clone(),
                description: self.description.to_string(),
                plots: vec![
                    self.plot(
                        name.clone(),
                        &self.plot_title(real.as_deref()),
                        objects.specs.len(),
                    ),
                    self.reliability_plot(&name, &self.plot_title(real.as_deref()))?,
                ],
            },
            config,
            units: self.units(context, &objects, counts, &plans, real, codebook),
        };
        Ok(run(&experiment, &context.options)?)
    }

    /// One unit per plan: its setting's model for its descriptor, evaluated on the setting's curves.
    fn units<'a>(
        &'a self,
        context: &'a PaperContext,
        objects: &Arc<Objects>,
        counts: DataCounts,
        plans: &[UnitPlan<'a>],
        real: Option<Arc<RealData>>,
        codebook: CodebookKind,
    ) -> Vec<Unit<'a, AccuracyRow, RecognitionDetail>> {
        plans
            .iter()
            .map(|plan| {
                let objects = Arc::clone(objects);
                let setting_counts = plan.setting.counts(counts);
                let training = training_config(context, codebook, setting_counts, objects.specs.len());
                let real = real.clone();
                let (setting, descriptor) = (plan.setting, plan.descriptor);
                Unit::with_detail(plan.key.clone(), move || {
                    let data = SettingData::new(context, &objects, setting, setting_counts);
                    self.unit_rows(&data, descriptor, &training, real.as_deref())
                })
            })
            .collect()
    }

    /// The accuracy plot of the sweep's rows, chance level at 1 / `objects`.
    pub(super) fn plot(&self, name: SafeName, title: &str, objects: usize) -> PlotSpec {
        let plot = PlotSpec::accuracy(name, title).with_chance(objects);
        match self.legend {
            Some(template) => plot.with_legend(template),
            None => plot,
        }
    }

    /// The reliability diagram of the sweep's curves, `<name>-reliability`, titled `title`.
    pub(super) fn reliability_plot(&self, name: &SafeName, title: &str) -> Result<PlotSpec, BoxError> {
        let plot = PlotSpec::reliability(
            SafeName::new(format!("{name}-reliability"))?,
            &format!("Calibration: {title}"),
        )?;
        Ok(match self.legend {
            Some(template) => plot.with_legend(template),
            None => plot,
        })
    }

    /// Every curve's levels are valid and of the same factors in the same order, so that every row
    /// of the experiment has the same columns.
    pub(super) fn check_factors(&self) -> Result<(), BoxError> {
        let mut curves = self.settings.iter().flat_map(|s| &s.curves);
        let Some(first) = curves.next() else {
            return Ok(());
        };
        for curve in std::iter::once(first).chain(curves) {
            curve
                .factors
                .check()
                .map_err(|e| format!("experiment '{}': {e}", self.name))?;
            if !curve.factors.factors().eq(first.factors.factors()) {
                return Err(format!(
                    "experiment '{}': curve '{}' has other factors than '{}': one header for all rows",
                    self.name, curve.factors, first.factors
                )
                .into());
            }
        }
        Ok(())
    }

    fn unit_plans(&self) -> Result<Vec<UnitPlan<'_>>, BoxError> {
        self.check_factors()?;
        let mut plans = Vec::new();
        for setting in &self.settings {
            for &descriptor in &self.descriptors {
                let mut key = SafeName::builder(descriptor.name());
                if !self.key_parameter.is_empty() {
                    key = key.param(self.key_parameter, &setting.label);
                }
                let key = key.build()?;
                plans.push(UnitPlan {
                    key,
                    setting,
                    descriptor,
                });
            }
        }
        Ok(plans)
    }

    /// The rows of one unit: the model of `data`'s setting for descriptor `kind` (trained, or
    /// loaded from the store), evaluated on every curve of the setting over all trials.
    fn unit_rows(
        &self,
        data: &SettingData,
        kind: DescriptorKind,
        training: &TrainConfig,
        real: Option<&RealData>,
    ) -> Result<RecognitionRows, BoxError> {
        let descriptor = kind.build();
        let model = data.judging_model(descriptor.as_ref(), training)?;
        let (mut rows, mut per_object, mut reliability) = (Vec::new(), Vec::new(), Vec::new());
        for curve in &data.setting.curves {
            let trials = match curve.test {
                TestData::Real => {
                    let real = real.ok_or("internal: the real recording was not loaded")?;
                    real_trials(
                        real,
                        descriptor.as_ref(),
                        &model,
                        data.context.seed,
                        data.counts.trials,
                    )?
                }
                test => data.dataset_trials(test, &model, descriptor.as_ref(), &curve.factors)?,
            };
            let mut table = ReliabilityTable::default();
            let mut meta = AccuracyCurve {
                experiment: self.name.to_string(),
                descriptor: kind.name().to_string(),
                factors: curve.factors.clone(),
                trial: 0,
                seed: data.context.seed,
                stream_seed: 0,
            };
            for (trial, (seed, object_trials)) in trials.iter().enumerate() {
                (meta.trial, meta.stream_seed) = (trial as u32, *seed);
                let (curve_rows, curve_objects, trial_table) =
                    trial_rows(&meta, &model, object_trials, &curve.factors, trial)?;
                rows.extend(curve_rows);
                per_object.extend(curve_objects);
                table.merge(&trial_table);
            }
            reliability.extend(meta.reliability_rows(&table));
        }
        Ok((rows, (per_object, reliability)))
    }
}

/// The rows of one trial of a curve: accuracy and reliability after every reading count up to the
/// longest object trial. One definition of accuracy (`recognize::AccuracyPoint`): every object
/// counts, an unread one as a miss; the per-object rows are the outcomes it counts; the reliability
/// table holds every belief of the trial (pooled over trials into the curve's).
fn trial_rows(
    meta: &AccuracyCurve,
    model: &TrainedModel,
    object_trials: &[Trial],
    curve: &Factors,
    trial: usize,
) -> Result<(Vec<AccuracyRow>, Vec<PerObjectRow>, ReliabilityTable), BoxError> {
    let longest = object_trials.iter().map(|t| t.readings.len()).max().unwrap_or(0);
    if longest == 0 {
        return Err(
            format!("curve '{curve}', trial {trial}: no converged test reading of any object").into(),
        );
    }
    let evaluation = evaluate(&model.bag, object_trials, ReadingRange::new(1, longest)?)?;
    Ok((
        meta.rows(&evaluation.accuracy),
        meta.object_rows(&evaluation)?,
        evaluation.reliability(),
    ))
}

/// The further tables of a recognition experiment: per-object outcomes and per-curve reliability.
pub(crate) type RecognitionDetail = (PerObjectRow, ReliabilityRow);

/// A recognition unit's rows: accuracy, and the per-object and reliability rows.
pub(crate) type RecognitionRows = (Vec<AccuracyRow>, (Vec<PerObjectRow>, Vec<ReliabilityRow>));

impl Setting {
    /// The scale's data counts with this setting's multiple of the training readings (at least
    /// one).
    pub(crate) fn counts(&self, counts: DataCounts) -> DataCounts {
        DataCounts {
            training_per_object: ((counts.training_per_object as f64 * self.training_fraction).round()
                as usize)
                .max(1),
            ..counts
        }
    }

    /// Whether the setting's posteriors are fitted on the arm's explorations in `context`: the
    /// setting asks for it and the run's posterior is calibrated.
    fn calibrated_on_arm(&self, context: &PaperContext) -> bool {
        self.calibrated_on == CalibratedOn::ArmExplorations
            && matches!(context.posterior(), PosteriorRule::Calibrated)
    }

    /// The sensor with the run's noise stream.
    pub(super) fn sensor_of_run(&self, context: &PaperContext) -> SensorConfig {
        SensorConfig {
            noise_seed: rng::substream(context.seed, NOISE_STREAM),
            ..self.sensor
        }
    }

    /// The controllers, told the sensor's noise width as a real controller knows its sensor's
    /// noise floor (see [`ControlConfig::expected_noise_fraction`]).
    pub(super) fn control(&self) -> Result<Valid<ControlConfig>, RangeError> {
        Valid::new(ControlConfig {
            expected_noise_fraction: self.sensor.noise_fraction,
            ..ControlConfig::default()
        })
    }
}

/// One setting of a sweep in one run: the data its units read, with the run's objects and the
/// setting's data counts.
pub(super) struct SettingData<'a> {
    pub context: &'a PaperContext,
    pub objects: &'a Arc<Objects>,
    pub setting: &'a Setting,
    /// The data counts of the setting (the scale's, with its training readings: [`Setting::counts`]).
    pub counts: DataCounts,
}

impl<'a> SettingData<'a> {
    /// `setting` in `context` over `objects`, with the setting's data `counts`.
    pub(super) fn new(
        context: &'a PaperContext,
        objects: &'a Arc<Objects>,
        setting: &'a Setting,
        counts: DataCounts,
    ) -> Self {
        Self {
            context,
            objects,
            setting,
            counts,
        }
    }

    fn sampler_request(&self, readings: usize, stream: u64) -> Result<DataRequest, RangeError> {
        Ok(DataRequest::new(
            self.objects,
            CollectPlan {
                mode: CollectMode::Sampler(Valid::new(self.setting.sampler)?),
                sensor: self.setting.sensor_of_run(self.context),
                control: self.setting.control()?,
                perturbation: PerturbationBounds::NONE,
                readings_per_object: readings,
                seed: rng::substream(self.context.seed, stream),
                start_pose: StartPose::Canonical,
                free_object: None,
            },
        ))
    }

    pub(super) fn training_request(&self) -> Result<DataRequest, RangeError> {
        self.sampler_request(self.counts.training_per_object, TRAINING_STREAM)
    }

    pub(super) fn validation_request(&self) -> Result<DataRequest, RangeError> {
        self.sampler_request(self.counts.validation_per_object, VALIDATION_STREAM)
    }

    /// The planner exploring each object blind with the arm at L = `local_probability`, the object
    /// held as `held` says, starting at `start_pose` and perturbed within `perturbation`,
    /// `readings` per object, seeded by the run's `stream`.
    fn planner_request(
        &self,
        local_probability: f64,
        (perturbation, held): (PerturbationBounds, Option<FreeBody>),
        start_pose: StartPose,
        readings: usize,
        stream: u64,
    ) -> Result<DataRequest, RangeError> {
        let config = PlannerConfig {
            local_probability,
            ..PlannerConfig::default()
        };
        Ok(DataRequest::new(
            self.objects,
            CollectPlan {
                mode: CollectMode::Planner(Valid::new(config.fitted_to(&self.objects.specs))?),
                sensor: self.setting.sensor_of_run(self.context),
                control: self.setting.control()?,
                perturbation,
                readings_per_object: readings,
                seed: rng::substream(self.context.seed, stream),
                start_pose,
                free_object: held,
            },
        ))
    }

    /// The arm's own explorations a model's posterior is calibrated on when it will recognise
    /// the arm's touches (`recognize::calibration`): the planner at each L of
    /// [`CALIBRATION_LOCAL_PROBABILITIES`] (0.5 and 1), the object fixed, as many readings per
    /// object as the validation set, as many explorations of each object at each L as there are
    /// test trials, each on a stream of its own (never a test trial's).
    ///
    /// Why both: L = 1 touches one region again and again, so its successive readings are more
    /// alike than L = 0.5's, and a tempering fitted on L = 0.5 alone left a stop at 0.95 right
    /// 94.7% of the time on L = 1 fixed over fifteen seeds; calibrated on both it is right
    /// 95.2-98.0% of the time on every curve (in a replay, as many more L = 0.5 explorations did
    /// not help; docs/measurements.md, "Calibrated on both strategies"). One exploration per object fitted
    /// the tempering on twelve paths and left the posterior overconfident (a stop at 0.99 never
    /// fired; "More than one calibration exploration").
    pub(super) fn calibration_requests(&self) -> Result<Vec<DataRequest>, RangeError> {
        let mut requests = Vec::new();
        for (i, local_probability) in CALIBRATION_LOCAL_PROBABILITIES.into_iter().enumerate() {
            requests.extend(self.planner_trials(
                local_probability,
                (PerturbationBounds::NONE, None),
                StartPose::Canonical,
                self.counts.validation_per_object,
                CALIBRATION_STREAM + 100 * i as u64,
            )?);
        }
        Ok(requests)
    }

    /// One planner dataset per trial, `readings` per object, trial `t` on stream
    /// `first_stream + t`, the object held as `held` says (a mocap body when `None`).
    pub(super) fn planner_trials(
        &self,
        local_probability: f64,
        (perturbation, held): (PerturbationBounds, Option<FreeBody>),
        start_pose: StartPose,
        readings: usize,
        first_stream: u64,
    ) -> Result<Vec<DataRequest>, RangeError> {
        (0..self.counts.trials)
            .map(|t| {
                self.planner_request(
                    local_probability,
                    (perturbation, held),
                    start_pose,
                    readings,
                    first_stream + t as u64,
                )
            })
            .collect()
    }

    /// The datasets of curve `test`, one per trial (none for real frames).
    pub(super) fn test_requests(&self, test: TestData) -> Result<Vec<DataRequest>, RangeError> {
        let trial_stream = |t: usize| TEST_STREAM + t as u64;
        match test {
            TestData::Validation => Ok(vec![self.validation_request()?]),
            TestData::Sampler => (0..self.counts.trials)
                .map(|t| self.sampler_request(self.counts.test_per_object, trial_stream(t)))
                .collect(),
            TestData::Planner {
                local_probability,
                perturbation,
            } => self.planner_trials(
                local_probability,
                (perturbation, None),
                StartPose::Canonical,
                self.counts.test_per_object,
                TEST_STREAM,
            ),
            TestData::Real => Ok(Vec::new()),
        }
    }

    /// Every dataset a unit of the setting reads.
    pub(super) fn requests(&self) -> Result<Vec<DataRequest>, RangeError> {
        let mut requests = vec![self.training_request()?, self.validation_request()?];
        for curve in &self.setting.curves {
            requests.extend(self.test_requests(curve.test)?);
        }
        if self.setting.calibrated_on_arm(self.context) {
            requests.extend(self.calibration_requests()?);
        }
        Ok(requests)
    }

    /// The model of `descriptor` trained by `training` on the setting's data, with the posterior
    /// the setting's curves are judged by: with [`CalibratedOn::ArmExplorations`] under the
    /// calibrated rule, its tempering and confidence map fitted again on the arm's explorations
    /// ([`Self::calibration_requests`]) in trials as long as a test run
    /// (`DataStore::arm_calibrated_model`, timed as training); otherwise as trained.
    pub(super) fn judging_model(
        &self,
        descriptor: &dyn Descriptor,
        training: &TrainConfig,
    ) -> Result<TrainedModel, BoxError> {
        let (data, validation) = (self.training_request()?, self.validation_request()?);
        let store = &self.context.store;
        if !self.setting.calibrated_on_arm(self.context) {
            return store.model(&data, &validation, descriptor, training);
        }
        store.arm_calibrated_model(
            &data,
            &validation,
            descriptor,
            training,
            &self.calibration_requests()?,
            self.counts.test_per_object,
        )
    }

    /// The trials of a curve read from datasets (every kind but real frames): per trial its seed
    /// and one [`Trial`] per object, the features of its converged readings in order.
    pub(super) fn dataset_trials(
        &self,
        test: TestData,
        model: &TrainedModel,
        descriptor: &dyn Descriptor,
        curve: &Factors,
    ) -> Result<Vec<(u64, Vec<Trial>)>, BoxError> {
        let readings = self.counts.test_per_object.max(self.counts.validation_per_object);
        self.test_requests(test)?
            .iter()
            .map(|request| {
                let data = self.context.store.dataset(request)?;
                model
                    .check_sensor(&data.header().sensor)
                    .map_err(|e| format!("test data of '{curve}': {e}"))?;
                let features = LabelledFeatures::from_dataset(&data, descriptor);
                Ok((
                    request.plan.seed,
                    make_trials(&features, model.bag.objects(), readings)?,
                ))
            })
            .collect()
    }
}

/// Model selection as in Sec. V-B1 (3 seeded restarts) over the cluster counts sized to the
/// problem ([`TrainConfig::with_grid_for`]: the planned training readings, since the grid is part of
/// the run's `config.json`, written before any data is collected), with `codebook`.
pub(super) fn training_config(
    context: &PaperContext,
    codebook: CodebookKind,
    counts: DataCounts,
    objects: usize,
) -> TrainConfig {
    selection_config(
        codebook,
        rng::substream(context.seed, MODEL_STREAM),
        counts.training_per_object,
        counts.validation_per_object,
        objects,
    )
}

/// The model-selection settings for a `codebook` on `training_per_object` training and
/// `validation_per_object` validation readings of each of `objects` objects, seeded with
/// `model_seed`; the PCA keeps the codebook's default share of the variance.
pub(super) fn selection_config(
    codebook: CodebookKind,
    model_seed: u64,
    training_per_object: usize,
    validation_per_object: usize,
    objects: usize,
) -> TrainConfig {
    // The validation readings are a dataset of their own: none is held out of the training ones.
    TrainConfig {
        codebook,
        restarts: 3,
        seed: model_seed,
        variance_kept: codebook.default_variance_kept(),
        trial_readings: validation_per_object.min(10),
        ..TrainConfig::default()
    }
    .with_grid_for(objects, training_per_object * objects, true)
}

/// The simulated counterpart of `sensor` for a recording of `real`'s grid at `pitch`: the
/// recording's pad ([`recorded_sensor`]) with `sensor`'s covering share of the shorter side, its
/// point spread for that covering, and `sensor`'s noise.
fn sensor_of_recording(sensor: &SensorConfig, real: &RealData, pitch: TaxelPitch) -> SensorConfig {
    let (pad, _) = recorded_sensor(real.rows, real.cols, Some(pitch));
    let shorter_m = |s: &SensorConfig| s.pad_width_m.min(s.pad_height_m);
    SensorConfig {
        noise_fraction: sensor.noise_fraction,
        ..SensorConfig::of_pad(
            real.rows,
            real.cols,
            pad.pad_width_m,
            pad.pad_height_m,
            Some(sensor.thickness_m / shorter_m(sensor) * shorter_m(&pad)),
            None,
        )
    }
}

/// The recorded frames as trials of the model's objects: each label's frames, preprocessed as in
/// Sec. V-F; trial 0 in file order, trial `t > 0` in the order of a seeded shuffle.
fn real_trials(
    real: &RealData,
    descriptor: &dyn Descriptor,
    model: &TrainedModel,
    seed: u64,
    trials: usize,
) -> Result<Vec<(u64, Vec<Trial>)>, BoxError> {
    if (real.rows, real.cols) != (model.sensor.rows, model.sensor.cols) {
        return Err(format!(
            "the real frames are {}x{} taxels but the simulated sensor is {}x{}",
            real.rows, real.cols, model.sensor.rows, model.sensor.cols
        )
        .into());
    }
    let preprocess = SimToRealPreprocess::default();
    let objects = model.bag.objects();
    let mut per_object: Vec<Vec<Vec<Vec<f64>>>> = vec![Vec::new(); objects.len()];
    for reading in &real.readings {
        let j = objects.iter().position(|o| *o == reading.label).ok_or_else(|| {
            format!(
                "{}: label '{}' is not a trained object",
                reading.place, reading.label
            )
        })?;
        per_object[j].push(descriptor.describe(&preprocess.apply(&reading.image)));
    }
    Ok((0..trials)
        .map(|t| {
            let trial_seed = rng::substream(rng::substream(seed, ORDERING_STREAM), t as u64);
            let mut order = rng::rng(trial_seed);
            let object_trials = per_object
                .iter()
                .enumerate()
                .filter(|(_, frames)| !frames.is_empty())
                .map(|(object, frames)| {
                    let mut readings = frames.clone();
                    if t > 0 {
                        readings.shuffle(&mut order);
                    }
                    Trial { object, readings }
                })
                .collect();
            (trial_seed, object_trials)
        })
        .collect())
}
