//! Beyond the paper: active touch by expected information gain (`active_touch`) against the
//! paper's blind exploration with L = 1 (its best, Fig. 8) and L = 0.5, on the 3D set with the
//! object fixed and perturbed after every reading (Sec. V-B4), and how many touches each needs
//! before a confidence stop would fire.
//!
//! The model is the end-to-end recipe's (`end-to-end`, "reachable"): three times the scale's
//! sampler readings per object from starts the arm can reach, with the run's codebook, its
//! posterior calibrated on the arm's own explorations (planner datasets at L = 0.5 and L = 1, each
//! on a stream of its own, `recognize::calibration`), each object's exploration one trial as long
//! as a test run (`test_per_object` touches). The L curves recognise the same planner datasets as
//! Figs. 8 and 10 (shared through `<out>/data`). The active curves cannot come from a
//! dataset collected beforehand: where the arm touches next depends on the model's belief, so each
//! unit explores with the trained model in the loop, with the random streams and sensor of the
//! L = 0.5 datasets (common random numbers) and no stop, `test_per_object` touches per object.
//!
//! The confidence stop needs no second run: the planner's draws do not depend on it, so a run with
//! the stop is the run without it cut at the touch where the stop fires ([`ConfidenceStop`], the
//! product's default: one guess held at the threshold over the last two touches). Each row adds,
//! for each threshold of [`REPORTED_STOPS`], the fraction of objects stopped by then (`confident`, the
//! cumulative distribution of touches-to-confidence) and the fraction stopped with the right guess
//! (`correct_at_stop`).

use std::sync::Arc;

use serde::ser::{SerializeStruct, Serializer};
use serde::{Deserialize, Deserializer, Serialize};

use super::context::Family;
use super::context::PaperContext;
use super::data::Objects;
use super::figures::{END_TO_END_TRAINING_FRACTION, default_sensor};
use super::recognition::{
    ArmCalibration, CalibratedOn, Curve, RecognitionDetail, RecognitionSweep, Setting, SettingData, TestData,
    training_config,
};
use super::scale::DataCounts;
use crate::active_touch::{
    ActiveRecognition, REPORTED_STOPS, TouchPlan, TouchRun, explore_recognizing, reported_stops, stops,
};
use crate::describe::{Descriptor, DescriptorKind};
use crate::experiment::accuracy::{AccuracyCurve, AccuracyRow, PerObjectRow, ReliabilityRow};
use crate::experiment::factor::{Factor, Factors};
use crate::experiment::layout::ExperimentDir;
use crate::experiment::name::SafeName;
use crate::experiment::plot::{Axis, PlotSpec};
use crate::experiment::progress::Progress;
use crate::experiment::runner::{Experiment, RunReport, run};
use crate::experiment::spec::ExperimentSpec;
use crate::experiment::tidy::{ReadCell, TidyRecord, deserialize_record, serialize_record};
use crate::experiment::unit::{BoxError, Unit};
use crate::explore::active::{ConfidenceStop, DEFAULT_CANDIDATES};
use crate::explore::collect::{CollectMode, CollectPlan};
use crate::explore::{PlannerConfig, SamplerConfig};
use crate::recognize::{
    CodebookKind, PosteriorRule, ReadingRange, ReliabilityTable, TrainConfig, TrainedModel, Trial, evaluate,
};
use crate::sim::PerturbationBounds;

pub const EXPERIMENT_NAME: &str = "active";
pub const DESCRIPTION: &str = "Beyond the paper: active touch by expected information gain vs L = 1 and L = 0.5 (3D set, fixed and perturbed; PF), with touches to 95% confidence";

/// The descriptor: Polar-Fourier, one of the paper's top three (Sec. V-B2) and the demo's.
const DESCRIPTOR: DescriptorKind = DescriptorKind::PolarFourier;

/// L of the active strategy's proposals: half local, half global candidates.
pub(super) const ACTIVE_LOCAL_PROBABILITY: f64 = 0.5;

/// One point of one curve: the columns of an [`AccuracyRow`] (so the accuracy plot and the
/// headline table read it) and the confidence stop's after them.
///
/// | column | meaning |
/// |---|---|
/// | `strategy` | `blind` (the planner's random local or global moves) or `active` (its candidates scored by expected information gain) |
/// | `local_probability` | L of the planner's moves, or of the active strategy's proposals (0.5) |
/// | `object_motion` | `fixed` or `perturbed` after every reading |
/// | `confident` | fraction of objects whose confidence stop ([`ConfidenceStop`]: one guess held at the threshold over the last `stop_held_readings` touches) fired within `n_readings` readings |
/// | `correct_at_stop` | fraction of the objects (all of them, as in `confident`) that stopped within `n_readings` readings with the right guess at the stop; `correct_at_stop / confident` is the share of the stopped runs that were right |
#[derive(Debug, Clone, PartialEq)]
pub struct ActiveRow {
    pub accuracy: AccuracyRow,
    /// Per threshold of [`REPORTED_STOPS`], in order: the fraction of objects stopped by `n_readings`
    /// readings, and of them stopped with the right guess.
    pub stops: [StopShare; 3],
}

/// The confidence stop at one threshold after some readings (the columns of [`ActiveRow`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StopShare {
    pub confident: f64,
    pub correct_at_stop: f64,
}

/// The column names of stop `i` of [`REPORTED_STOPS`].
fn stop_columns(i: usize) -> (&'static str, &'static str) {
    match i {
        0 => ("confident_0.9", "correct_at_stop_0.9"),
        1 => ("confident", "correct_at_stop"),
        _ => ("confident_0.99", "correct_at_stop_0.99"),
    }
}

/// An `AccuracyRow`'s columns, then each stop's two: written by hand rather than by `tidy_row!`,
/// since the stop columns are named by `stop_columns` rather than by fields.
impl TidyRecord for ActiveRow {
    fn width(&self) -> usize {
        self.accuracy.width() + 2 * self.stops.len()
    }

    fn serialize_columns<S: SerializeStruct>(&self, row: &mut S) -> Result<(), S::Error> {
        self.accuracy.serialize_columns(row)?;
        for (i, stop) in self.stops.iter().enumerate() {
            let (confident, correct) = stop_columns(i);
            row.serialize_field(confident, &stop.confident)?;
            row.serialize_field(correct, &stop.correct_at_stop)?;
        }
        Ok(())
    }
}

impl Serialize for ActiveRow {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serialize_record("ActiveRow", self, serializer)
    }
}

impl<'de> Deserialize<'de> for ActiveRow {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserialize_record(deserializer, |cells| {
            let stop = |i: usize| -> Result<StopShare, String> {
                let (confident, correct) = stop_columns(i);
                Ok(StopShare {
                    confident: f64::read_cell(cells, confident)?,
                    correct_at_stop: f64::read_cell(cells, correct)?,
                })
            };
            Ok(Self {
                accuracy: AccuracyRow::from_cells(cells)?,
                stops: [stop(0)?, stop(1)?, stop(2)?],
            })
        })
    }
}

/// The legend's name of a curve in both plots.
const CURVE_LABEL: &str = "{strategy} L={local_probability} {object_motion}";

/// A curve's levels: `strategy` (`blind` or `active`) at L = `local_probability`, the object `motion`.
fn levels(strategy: &str, local_probability: f64, motion: &str) -> Factors {
    Factors::new([
        (Factor::Strategy, strategy.to_string()),
        (Factor::LocalProbability, local_probability.to_string()),
        (Factor::ObjectMotion, motion.to_string()),
    ])
}

fn perturbed() -> PerturbationBounds {
    PerturbationBounds::new(10.0, 0.1).unwrap_or(PerturbationBounds::NONE)
}

fn object_states() -> [(&'static str, PerturbationBounds); 2] {
    [("fixed", PerturbationBounds::NONE), ("perturbed", perturbed())]
}

/// The L curves, as a sweep whose datasets are those of Figs. 8 and 10.
pub fn sweep() -> RecognitionSweep {
    let mut curves = Vec::new();
    for l in [1.0, 0.5] {
        for (state, perturbation) in object_states() {
            curves.push(Curve {
                factors: levels("blind", l, state),
                test: TestData::Planner {
                    local_probability: l,
                    perturbation,
                },
            });
        }
    }
    RecognitionSweep {
        name: EXPERIMENT_NAME,
        description: DESCRIPTION,
        title: "Active touch (expected information gain) vs blind exploration",
        // One unit, keyed by the descriptor alone (`run_active`).
        key_parameter: "",
        legend: Some("strategy = {strategy} L={local_probability} {object_motion}"),
        family: Family::Shapes,
        descriptors: vec![DESCRIPTOR],
        settings: vec![Setting {
            label: "active".into(),
            sensor: default_sensor(),
            sampler: SamplerConfig {
                reachable_by_arm: true,
                ..SamplerConfig::default()
            },
            training_fraction: END_TO_END_TRAINING_FRACTION,
            calibrated_on: CalibratedOn::ArmExplorations,
            curves,
        }],
    }
}

#[derive(Serialize)]
struct ActiveConfig<'a> {
    sweep: &'a RecognitionSweep,
    active_local_probability: f64,
    active_candidates: usize,
    neighbourhood_m: f64,
    stops: [f64; 3],
    /// Touches a guess must hold a stop's threshold over for the stop to fire.
    stop_held_readings: usize,
    /// The posterior: `calibrated` on the arm's explorations (`arm_calibration`), or the paper's
    /// `eq15`.
    posterior: PosteriorRule,
    #[serde(skip_serializing_if = "Option::is_none")]
    arm_calibration: Option<ArmCalibration>,
    scale: f64,
    counts: DataCounts,
    seed: u64,
    object_set_id: String,
    objects: Vec<String>,
    training: TrainConfig,
}

/// Runs the experiment in `context` (one unit: the model, the L curves and the active curves).
pub fn run_active(context: &PaperContext, codebook: CodebookKind) -> Result<RunReport, BoxError> {
    let sweep = sweep();
    let objects = context.objects(Family::Shapes)?;
    let counts = sweep.settings[0].counts(context.scale.counts());
    let training = training_config(context, codebook, counts, objects.specs.len());
    let name = SafeName::new(EXPERIMENT_NAME)?;
    let key = SafeName::builder(DESCRIPTOR.name()).build()?;
    let dir = ExperimentDir::new(&context.options.out, &name);
    if context.options.shard.contains(0) && !dir.unit_csv(&key).exists() {
        let data = SettingData::new(context, &objects, &sweep.settings[0], counts);
        context.store.prepare(&data.requests()?, dir.root())?;
    }
    let neighbourhood_m = PlannerConfig::default().grid_cell_m;
    let unit = {
        let work = ActiveUnit {
            context,
            sweep: &sweep,
            objects: Arc::clone(&objects),
            counts,
            training: training.clone(),
            neighbourhood_m,
        };
        Unit::<_, RecognitionDetail>::with_detail(key, move || work.rows())
    };
    let experiment = Experiment {
        spec: ExperimentSpec {
            name: name.clone(),
            description: DESCRIPTION.to_string(),
            plots: vec![
                sweep.plot(name.clone(), sweep.title, objects.specs.len()),
                sweep.reliability_plot(&name, sweep.title)?,
                PlotSpec::lines(
                    SafeName::new("active-confidence")?,
                    "Objects recognised with 95% confidence (the stop's touches, cumulative)",
                    Axis::new("n_readings", "number of readings"),
                    vec![Axis::new("confident", "objects confident (fraction)")],
                    &["strategy", "local_probability", "object_motion"],
                )
                .with_legend(CURVE_LABEL),
            ],
        },
        config: ActiveConfig {
            sweep: &sweep,
            active_local_probability: ACTIVE_LOCAL_PROBABILITY,
            active_candidates: DEFAULT_CANDIDATES,
            neighbourhood_m,
            stops: REPORTED_STOPS,
            stop_held_readings: ConfidenceStop::DEFAULT_HELD_READINGS.get(),
            posterior: context.posterior(),
            arm_calibration: sweep.arm_calibration(context, counts),
            scale: context.scale.fraction(),
            counts,
            seed: context.seed,
            object_set_id: objects.set.id(),
            objects: objects.names(),
            training: training.clone(),
        },
        units: vec![unit],
    };
    Ok(run(&experiment, &context.options)?)
}

/// What the experiment's one unit works from.
struct ActiveUnit<'a> {
    context: &'a PaperContext,
    sweep: &'a RecognitionSweep,
    objects: Arc<Objects>,
    counts: DataCounts,
    training: TrainConfig,
    neighbourhood_m: f64,
}

type Rows = (Vec<ActiveRow>, (Vec<PerObjectRow>, Vec<ReliabilityRow>));

impl ActiveUnit<'_> {
    /// The data of the sweep's one setting.
    fn data(&self) -> SettingData<'_> {
        SettingData::new(self.context, &self.objects, &self.sweep.settings[0], self.counts)
    }

    /// One model, then the planner's L curves (Figs. 8 and 10's datasets), then the active
    /// curve for the object fixed and perturbed.
    fn rows(&self) -> Result<Rows, BoxError> {
        let descriptor = DESCRIPTOR.build();
        let data = self.data();
        let model = data.judging_model(descriptor.as_ref(), &self.training)?;
        let (mut rows, mut per_object, mut reliability) = (Vec::new(), Vec::new(), Vec::new());
        for curve in &self.sweep.settings[0].curves {
            let (curve_rows, (curve_objects, curve_reliability)) =
                self.planner_curve(curve, &model, descriptor.as_ref())?;
            rows.extend(curve_rows);
            per_object.extend(curve_objects);
            reliability.extend(curve_reliability);
        }
        for (curve_rows, (curve_objects, curve_reliability)) in
            self.active_curves(&model, descriptor.as_ref())?
        {
            rows.extend(curve_rows);
            per_object.extend(curve_objects);
            reliability.extend(curve_reliability);
        }
        Ok((rows, (per_object, reliability)))
    }

    /// An L curve: the planner's test datasets recognised by `model`.
    fn planner_curve(
        &self,
        curve: &Curve,
        model: &TrainedModel,
        descriptor: &dyn Descriptor,
    ) -> Result<Rows, BoxError> {
        let trials = self
            .data()
            .dataset_trials(curve.test, model, descriptor, &curve.factors)?;
        curve_rows(
            self.sweep,
            model,
            &curve.factors,
            &trials,
            self.counts,
            self.context.seed,
        )
    }

    /// The active curves with the object fixed and perturbed ([`object_states`]): every trial's
    /// objects explored with `model` in the loop under the plans of the L = 0.5 datasets with the
    /// same perturbation (same sensor, seeds, objects). Both curves' explorations share one pass
    /// over the pool ([`crate::queue`]), the perturbed ones (the longer) first, so that the pool
    /// stays busy to the end instead of idling at the end of each curve while its slowest
    /// exploration finishes.
    fn active_curves(
        &self,
        model: &TrainedModel,
        descriptor: &dyn Descriptor,
    ) -> Result<Vec<Rows>, BoxError> {
        let objects = &self.objects;
        let states = object_states();
        let bases = states
            .iter()
            .map(|&(_, perturbation)| {
                self.data().test_requests(TestData::Planner {
                    local_probability: ACTIVE_LOCAL_PROBABILITY,
                    perturbation,
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let jobs: Vec<(usize, usize, usize)> = (0..states.len())
            .rev()
            .flat_map(|s| {
                (0..bases[s].len()).flat_map(move |t| (0..objects.specs.len()).map(move |o| (s, t, o)))
            })
            .collect();
        // The curves are one unit of the run, saved when whole: the bar says how far they are.
        let progress = Progress::new("active touch", jobs.len(), "objects explored");
        // The workers take the explorations in order, so the pass ends on fixed ones; the first
        // failed exploration stops the pass.
        let explored: Vec<Trial> = crate::queue::run_in_order(jobs.len(), |i| {
            let (s, t, o) = jobs[i];
            let trial = active_trial(
                &bases[s][t].plan,
                objects,
                o,
                model,
                descriptor,
                self.counts.test_per_object,
                self.neighbourhood_m,
            );
            progress.inc();
            trial
        })?;
        progress.finish(explored.len());
        let objects_per_trial = objects.specs.len().max(1);
        states
            .iter()
            .enumerate()
            .map(|(s, &(state, _))| {
                let of_state = jobs.iter().zip(&explored).filter(|((js, ..), _)| *js == s);
                let trials_of_state: Vec<Trial> = of_state.map(|(_, trial)| trial.clone()).collect();
                let trials: Vec<(u64, Vec<Trial>)> = bases[s]
                    .iter()
                    .zip(trials_of_state.chunks(objects_per_trial))
                    .map(|(request, chunk)| (request.plan.seed, chunk.to_vec()))
                    .collect();
                curve_rows(
                    self.sweep,
                    model,
                    &levels("active", ACTIVE_LOCAL_PROBABILITY, state),
                    &trials,
                    self.counts,
                    self.context.seed,
                )
            })
            .collect()
    }
}

/// Object `index` explored actively under `plan` (a planner plan) with `model` in the loop: the
/// features of its converged touches, in order.
fn active_trial(
    plan: &CollectPlan,
    objects: &Objects,
    index: usize,
    model: &TrainedModel,
    descriptor: &dyn Descriptor,
    touches: usize,
    neighbourhood_m: f64,
) -> Result<Trial, BoxError> {
    let spec = &objects.specs[index];
    let object = model
        .bag
        .models()
        .object_index(&spec.name)
        .ok_or_else(|| format!("object '{}' is not in the trained model", spec.name))?;
    let mut recognition = ActiveRecognition::new(model, neighbourhood_m)?;
    let run = explore_actively(plan, objects, index, &mut recognition, touches)?;
    let readings = run
        .touches
        .iter()
        .map(|t| descriptor.describe(&t.reading.image))
        .collect();
    Ok(Trial { object, readings })
}

/// Object `index` of `objects` explored under `plan` (a planner plan: its start, sensor, random
/// streams and perturbation) by the active strategy, `recognition` in the loop scoring
/// [`DEFAULT_CANDIDATES`] candidates per iteration, until `touches` converged touches (no stop).
pub(super) fn explore_actively(
    plan: &CollectPlan,
    objects: &Objects,
    index: usize,
    recognition: &mut ActiveRecognition<'_>,
    touches: usize,
) -> Result<TouchRun, BoxError> {
    let CollectMode::Planner(config) = plan.mode else {
        return Err("internal: the active curve's plan is not a planner plan".into());
    };
    let spec = &objects.specs[index];
    let (mut scene, mut planner) = plan.planner_for(spec, index, config)?;
    Ok(explore_recognizing(
        &mut planner,
        &mut scene,
        &spec.name,
        recognition,
        TouchPlan {
            budget: touches,
            active_candidates: Some(DEFAULT_CANDIDATES),
            stop_at_confidence: None,
        },
        &mut |_| {},
    )?)
}

/// The rows of one curve: accuracy and reliability as every recognition figure defines them
/// ([`evaluate`]) with the confidence stop's columns, the per-object outcomes they count, and the
/// curve's reliability table pooled over its trials.
fn curve_rows(
    sweep: &RecognitionSweep,
    model: &TrainedModel,
    factors: &Factors,
    trials: &[(u64, Vec<Trial>)],
    counts: DataCounts,
    run_seed: u64,
) -> Result<Rows, BoxError> {
    let (mut rows, mut per_object) = (Vec::new(), Vec::new());
    let (mut table, mut curve) = (ReliabilityTable::default(), None);
    for (trial, (seed, object_trials)) in trials.iter().enumerate() {
        let longest = object_trials.iter().map(|t| t.readings.len()).max().unwrap_or(0);
        if longest == 0 {
            return Err(
                format!("curve '{factors}', trial {trial}: no converged test reading of any object").into(),
            );
        }
        let evaluation = evaluate(&model.bag, object_trials, ReadingRange::new(1, longest)?)?;
        let stops_at = reported_stops()
            .map(|stop| stops(&evaluation, object_trials.len(), stop, counts.test_per_object));
        let meta = AccuracyCurve {
            experiment: sweep.name.to_string(),
            descriptor: DESCRIPTOR.name().to_string(),
            factors: factors.clone(),
            trial: trial as u32,
            seed: run_seed,
            stream_seed: *seed,
        };
        let objects = object_trials.len().max(1) as f64;
        for accuracy in meta.rows(&evaluation.accuracy) {
            let n = accuracy.n_readings as usize;
            let share = |stops: &[Option<(usize, bool)>]| {
                let stopped: Vec<&(usize, bool)> = stops.iter().flatten().filter(|(k, _)| *k <= n).collect();
                StopShare {
                    confident: stopped.len() as f64 / objects,
                    correct_at_stop: stopped.iter().filter(|(_, right)| *right).count() as f64 / objects,
                }
            };
            rows.push(ActiveRow {
                accuracy,
                stops: [share(&stops_at[0]), share(&stops_at[1]), share(&stops_at[2])],
            });
        }
        per_object.extend(meta.object_rows(&evaluation)?);
        table.merge(&evaluation.reliability());
        curve = Some(meta);
    }
    let reliability = curve.map_or_else(Vec::new, |meta| meta.reliability_rows(&table));
    Ok((rows, (per_object, reliability)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blind_and_active_curves_share_the_factor_columns() {
        let sweep = sweep();
        sweep.check_factors().unwrap_or_else(|e| panic!("{e}"));
        let active = levels("active", ACTIVE_LOCAL_PROBABILITY, "fixed");
        let blind = &sweep.settings[0].curves[0].factors;
        assert!(active.factors().eq(blind.factors()));
        assert_eq!(
            active.to_string(),
            "strategy = active, local_probability = 0.5, object_motion = fixed"
        );
    }
}
