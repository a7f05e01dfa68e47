//! Fig. 16b (Sec. V-E): recognition trained and tested on recorded sensor frames alone.
//!
//! The paper pressed the physical sensor on the uppercase vowels (384 readings per letter), pruned
//! the readings where the letter did not touch the sensor, divided the rest at random into 200
//! training, 50 validation and 100 test readings per letter, trained and tested as in simulation,
//! and averaged over 7 trials of this whole division, training and testing process.
//!
//! Here, per trial `t`:
//! 1. frames whose peak (largest taxel, in [0, 1] of the sensing range) is below the contact
//!    threshold are dropped before any split ([`prune`]; the count per label goes to `config.json`);
//! 2. each label's remaining frames are split with [`split_per_label`] under the seed
//!    `substream(substream(seed, SPLIT_STREAM), t)` into the sizes of [`scaled_split_sizes`]; a
//!    recording that keeps several frames of one press (a contact, `dataset::recorded`) is split
//!    by contact, so no press lends frames to both training and test, and the sizes count
//!    contacts (a recording of single frames splits exactly as before: each frame its contact);
//! 3. a model is trained per descriptor on the training part, its codebook size chosen on the
//!    validation part (Sec. V-B1), and each label's test frames are recognised touch by touch.
//!
//! Calibrating elements against each other is the recording's business (a calibration file on
//! import); the square root and blur of Sec. V-F exist to bridge simulation and the real pad and
//! are off by default, since training and test frames here come from the same sensor.

use std::collections::BTreeMap;
use std::sync::Arc;

use serde::Serialize;

use super::context::PaperContext;
use super::real_frames_options::RealFramesOptions;
use super::recognition::{RecognitionDetail, RecognitionRows, selection_config};
use super::timing::PhaseClock;
use crate::dataset::recorded::{RealData, RealReading};
use crate::dataset::{ContactStatus, Dataset, TaxelPitch};
use crate::describe::{Descriptor, DescriptorKind};
use crate::experiment::accuracy::AccuracyCurve;
use crate::experiment::factor::Factors;
use crate::experiment::name::SafeName;
use crate::experiment::plot::PlotSpec;
use crate::experiment::runner::{Experiment, RunReport, run};
use crate::experiment::spec::ExperimentSpec;
use crate::experiment::unit::{BoxError, Unit};
use crate::paper::sim_to_real::{GaussianBlur, square_root};
use crate::paper::split::{Split, SplitSizes, split_per_label};
use crate::recognize::{
    CodebookKind, Evaluation, LabelledFeatures, PosteriorRule, ReadingRange, ReliabilityTable, TrainConfig,
    Trial, evaluate, train,
};
use crate::rng;
use crate::tactile::TactileImage;
use crate::valid::{Check, Valid};

/// The command-line name.
pub const EXPERIMENT_NAME: &str = "real-frames";
/// Streams of the experiment seed (see [`crate::rng::substream`]).
const SPLIT_STREAM: u64 = 6;
const MODEL_STREAM: u64 = 7;

/// Frames kept and dropped of one label.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct PruneCount {
    pub kept: usize,
    pub dropped: usize,
}

/// The frames whose peak reaches `contact_threshold`, in file order, and the counts per label
/// (Sec. V-E: "pruned of those configurations for which that particular letter did not make
/// contact with the sensor").
pub fn prune(real: &RealData, contact_threshold: f64) -> (Vec<&RealReading>, BTreeMap<String, PruneCount>) {
    let mut counts: BTreeMap<String, PruneCount> = BTreeMap::new();
    let mut kept = Vec::new();
    for reading in &real.readings {
        let count = counts
            .entry(reading.label.clone())
            .or_insert(PruneCount { kept: 0, dropped: 0 });
        if touched(reading, contact_threshold) {
            count.kept += 1;
            kept.push(reading);
        } else {
            count.dropped += 1;
        }
    }
    (kept, counts)
}

/// Whether the frame's peak (largest taxel) reaches `contact_threshold`: the letter touched the
/// sensor.
fn touched(reading: &RealReading, contact_threshold: f64) -> bool {
    reading.image.values().iter().copied().fold(0.0, f64::max) >= contact_threshold
}

/// The recording as a taction dataset (`taction dataset import`), so that `train` and `recognize`
/// take recorded frames: every frame a reading of its label, `converged` when it touched and
/// `no_contact` when [`prune`] drops it, its image as this experiment describes it (square root and
/// blur when `options` ask). `object_set` names the recording in the dataset's header, `pitch`
/// its taxels' spacing when its maker gave it (else the pad's size is filed as unknown,
/// [`recorded_sensor`](crate::dataset::recorded_sensor)).
pub fn recorded_dataset(
    real: &RealData,
    options: &RealFramesOptions,
    object_set: &str,
    pitch: Option<TaxelPitch>,
) -> Result<Dataset, BoxError> {
    options.check()?;
    let blur = GaussianBlur::new(options.blur_sigma_taxels)?;
    let generator = format!(
        "recorded {}, pruned below {} of the range{}{}",
        real.frames_words(),
        options.contact_threshold,
        if options.square_root {
            ", square-rooted"
        } else {
            ""
        },
        if options.blur_sigma_taxels > 0.0 {
            format!(", blurred by {} taxels", options.blur_sigma_taxels)
        } else {
            String::new()
        }
    );
    Ok(real.to_dataset(object_set, &generator, pitch, |frame| {
        let status = if touched(frame, options.contact_threshold) {
            ContactStatus::Converged
        } else {
            ContactStatus::NoContact
        };
        (preprocess(&frame.image, options, &blur), status)
    })?)
}

/// A label with fewer frames than the split's three parts.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{frames} frames of a label after pruning; the split needs at least 3 (training, validation, test)")]
pub struct TooFewFrames {
    pub frames: usize,
}

/// Readings per label in each part: the paper's 200 / 50 / 100 when every label keeps at least
/// 350 frames and the scale is 1. Otherwise every label uses
/// `n = min(smallest label's kept frames, max(7, round(350 * scale)))` frames, divided in the
/// paper's proportions 4 : 1 : 2: validation `max(1, floor(n / 7))`, test `max(1, floor(2n / 7))`,
/// training the rest. Every label gets the same sizes so that no label is favoured by the prior
/// the data implies. At least 3 frames per label are needed.
pub fn scaled_split_sizes(smallest_label: usize, scale: f64) -> Result<SplitSizes, TooFewFrames> {
    let paper = SplitSizes::PAPER;
    let wanted = ((paper.total() as f64 * scale).round() as usize).max(7);
    let n = smallest_label.min(wanted);
    if n >= paper.total() {
        return Ok(paper);
    }
    if n < 3 {
        return Err(TooFewFrames { frames: n });
    }
    let validation = (n / 7).max(1);
    let test = (2 * n / 7).max(1);
    Ok(SplitSizes {
        train: n - validation - test,
        validation,
        test,
    })
}

/// The frame as the descriptors see it: square-rooted and blurred when asked.
fn preprocess(image: &TactileImage, options: &RealFramesOptions, blur: &GaussianBlur) -> TactileImage {
    let image = if options.square_root {
        square_root(image)
    } else {
        image.clone()
    };
    if options.blur_sigma_taxels > 0.0 {
        blur.apply(&image)
    } else {
        image
    }
}

/// Everything the rows depend on, written as the run's `config.json`.
#[derive(Serialize)]
struct RealFramesConfig<'a> {
    recording: &'a str,
    rows: usize,
    cols: usize,
    scale: f64,
    seed: u64,
    options: &'a RealFramesOptions,
    labels: Vec<String>,
    /// Frames kept and dropped by pruning, per label.
    pruning: &'a BTreeMap<String, PruneCount>,
    /// Contacts that kept frames, per label, when the recording groups frames into contacts: the
    /// split's sizes count these. Absent for a recording of single frames.
    #[serde(skip_serializing_if = "Option::is_none")]
    contacts: Option<BTreeMap<String, usize>>,
    /// Readings (or contacts) per label in each part of every trial's split.
    split: SplitPerLabel,
    descriptors: Vec<&'static str>,
    training: &'a TrainConfig,
}

#[derive(Serialize)]
struct SplitPerLabel {
    train: usize,
    validation: usize,
    test: usize,
}

/// Fig. 16b's description in `experiment list`.
pub const DESCRIPTION: &str = "Fig. 16b: trained and tested on recorded frames (--real), pruned of non-contacts, split per letter 200/50/100, 7 trials, six descriptors";

/// Runs Fig. 16b on the context's recording, every model with `codebook`: one unit per
/// descriptor, each running every trial.
pub fn run_real_frames(context: &PaperContext, codebook: CodebookKind) -> Result<RunReport, BoxError> {
    let options = &context.real_frames;
    options.check()?;
    let real = context.real_data()?;
    let (kept, pruning) = prune(&real, options.contact_threshold);
    let labels: Vec<String> = pruning.keys().cloned().collect();
    let contacts = real.has_contacts().then(|| contacts_per_label(&kept));
    let sizes = split_sizes(context, &pruning, contacts.as_ref())?;
    let training = selection_config(
        codebook,
        rng::substream(context.seed, MODEL_STREAM),
        sizes.train,
        sizes.validation,
        labels.len(),
    );
    let plan = Arc::new(TrialPlan {
        kept: kept.into_iter().cloned().collect(),
        labels,
        sizes,
        training,
        options,
        blur: GaussianBlur::new(options.blur_sigma_taxels)?,
        seed: context.seed,
        posterior: context.posterior(),
        clock: &context.store.clock,
    });
    let name = SafeName::new(EXPERIMENT_NAME)?;
    let units = DescriptorKind::PAPER
        .iter()
        .map(|&kind| {
            let key = SafeName::builder(kind.name()).build()?;
            let plan = Arc::clone(&plan);
            Ok(Unit::<_, RecognitionDetail>::with_detail(key, move || {
                plan.descriptor_rows(kind)
            }))
        })
        .collect::<Result<Vec<_>, BoxError>>()?;
    let experiment = Experiment {
        spec: ExperimentSpec {
            name: name.clone(),
            description: DESCRIPTION.to_string(),
            plots: vec![
                PlotSpec::accuracy(
                    name.clone(),
                    &format!("Trained and tested on {}", real.frames_words()),
                )
                .with_chance(plan.labels.len()),
                PlotSpec::reliability(
                    SafeName::new(format!("{name}-reliability"))?,
                    &format!("Calibration: trained and tested on {}", real.frames_words()),
                )?,
            ],
        },
        config: plan.config(context, &real, (&pruning, contacts)),
        units,
    };
    Ok(run(&experiment, &context.options)?)
}

/// The split's sizes per label (see [`scaled_split_sizes`]), set by the label with the fewest frames
/// kept, or the fewest `contacts` when the recording groups frames into contacts; recognition
/// needs at least two labels.
fn split_sizes(
    context: &PaperContext,
    pruning: &BTreeMap<String, PruneCount>,
    contacts: Option<&BTreeMap<String, usize>>,
) -> Result<SplitSizes, BoxError> {
    if pruning.len() < 2 {
        return Err(format!(
            "{}: recognition needs at least 2 labels, the recording has {}",
            context.real.origin,
            pruning.len()
        )
        .into());
    }
    let (smallest_label, smallest) = pruning
        .iter()
        .map(|(label, c)| {
            let kept = contacts.map_or(c.kept, |counts| counts.get(label).copied().unwrap_or(0));
            (label.as_str(), kept)
        })
        .min_by_key(|(_, kept)| *kept)
        .ok_or("internal: no labels")?;
    Ok(
        scaled_split_sizes(smallest, context.scale.fraction()).map_err(|e| {
            let e = match contacts {
                Some(_) => e.to_string().replacen("frames", "contacts", 1),
                None => e.to_string(),
            };
            format!(
                "{}: label '{smallest_label}': {e} (--contact-threshold {} dropped {} of its frames)",
                context.real.origin, context.real_frames.contact_threshold, pruning[smallest_label].dropped
            )
        })?,
    )
}

/// How many contacts of each label kept frames (a contact's frames are consecutive,
/// [`contacts_of`]).
fn contacts_per_label(kept: &[&RealReading]) -> BTreeMap<String, usize> {
    let mut counts = BTreeMap::new();
    for contact in contacts_of(kept.iter().copied()) {
        *counts.entry(contact[0].label.clone()).or_insert(0) += 1;
    }
    counts
}

/// The frames grouped into contacts, in order: consecutive frames of one contact number together,
/// a frame without one alone (the importer keeps a contact's frames consecutive,
/// `dataset::recorded`).
fn contacts_of<'a>(frames: impl IntoIterator<Item = &'a RealReading>) -> Vec<Vec<&'a RealReading>> {
    let mut contacts: Vec<Vec<&RealReading>> = Vec::new();
    for frame in frames {
        match contacts.last_mut() {
            Some(open) if frame.contact.is_some() && open[0].contact == frame.contact => open.push(frame),
            _ => contacts.push(vec![frame]),
        }
    }
    contacts
}

/// What every trial of every descriptor shares: the frames kept, their labels, the split's sizes,
/// the training (its seed split per trial) and the frames' preprocessing.
struct TrialPlan<'a> {
    kept: Vec<RealReading>,
    labels: Vec<String>,
    sizes: SplitSizes,
    training: TrainConfig,
    options: &'a RealFramesOptions,
    blur: GaussianBlur,
    seed: u64,
    posterior: PosteriorRule,
    /// The run's clock, charged the training (`timing.rs`).
    clock: &'a PhaseClock,
}

impl TrialPlan<'_> {
    /// The run's `config.json`.
    fn config<'c>(
        &'c self,
        context: &'c PaperContext,
        real: &RealData,
        (pruning, contacts): (&'c BTreeMap<String, PruneCount>, Option<BTreeMap<String, usize>>),
    ) -> RealFramesConfig<'c> {
        RealFramesConfig {
            recording: &context.real.origin,
            rows: real.rows,
            cols: real.cols,
            scale: context.scale.fraction(),
            seed: self.seed,
            options: self.options,
            labels: self.labels.clone(),
            pruning,
            contacts,
            split: SplitPerLabel {
                train: self.sizes.train,
                validation: self.sizes.validation,
                test: self.sizes.test,
            },
            descriptors: DescriptorKind::PAPER.iter().map(|k| k.name()).collect(),
            training: &self.training,
        }
    }

    /// Every trial's accuracy rows of one descriptor, the per-label outcomes they count, and the
    /// reliability table of the descriptor's curve, pooled over its trials.
    fn descriptor_rows(&self, kind: DescriptorKind) -> Result<RecognitionRows, BoxError> {
        let descriptor = kind.build();
        let (mut rows, mut per_object) = (Vec::new(), Vec::new());
        let mut table = ReliabilityTable::default();
        let mut curve = None;
        for trial in 0..self.options.trials {
            let evaluation = self.evaluate_trial(descriptor.as_ref(), trial)?;
            let meta = AccuracyCurve {
                experiment: EXPERIMENT_NAME.to_string(),
                descriptor: kind.name().to_string(),
                // The figure varies only the descriptor.
                factors: Factors::none(),
                trial: trial as u32,
                seed: self.seed,
                stream_seed: trial_seed(self.seed, trial),
            };
            // One definition of accuracy (`recognize::AccuracyPoint`): every label counts.
            rows.extend(meta.rows(&evaluation.accuracy));
            per_object.extend(meta.object_rows(&evaluation)?);
            table.merge(&evaluation.reliability());
            curve = Some(meta);
        }
        let reliability = curve.map_or_else(Vec::new, |meta| meta.reliability_rows(&table));
        Ok((rows, (per_object, reliability)))
    }

    /// Trial `trial`: its split, a model trained and selected on it, each label's test frames
    /// recognised touch by touch.
    fn evaluate_trial(&self, descriptor: &dyn Descriptor, trial: usize) -> Result<Evaluation, BoxError> {
        let split = trial_split(&self.kept, self.sizes, self.seed, trial)?;
        let trial_training = TrainConfig {
            seed: rng::substream(self.training.seed, trial as u64),
            ..self.training.clone()
        };
        let config = Valid::new(trial_training)?;
        let (training, validation) = (
            self.describe(descriptor, &split.train)?,
            self.describe(descriptor, &split.validation)?,
        );
        let trained = self
            .clock
            .training(|| train(&config, &training, Some(&validation), &mut |_| {}))?;
        let test = self.describe(descriptor, &split.test)?;
        let trials: Vec<Trial> = (0..self.labels.len())
            .map(|object| Trial {
                object,
                readings: test.readings(object).to_vec(),
            })
            .collect();
        let longest = trials.iter().map(|t| t.readings.len()).max().unwrap_or(0);
        let bag = trained.bag.with_posterior(self.posterior);
        Ok(evaluate(&bag, &trials, ReadingRange::new(1, longest)?)?)
    }

    /// The features of `frames`, grouped by label.
    fn describe(
        &self,
        descriptor: &dyn Descriptor,
        frames: &[&RealReading],
    ) -> Result<LabelledFeatures, BoxError> {
        let mut per_label: Vec<Vec<Vec<Vec<f64>>>> = vec![Vec::new(); self.labels.len()];
        for frame in frames {
            let j = self
                .labels
                .iter()
                .position(|l| *l == frame.label)
                .ok_or("internal: a frame of an unknown label")?;
            per_label[j].push(describe_frame(descriptor, &frame.image, self.options, &self.blur));
        }
        Ok(LabelledFeatures::new(self.labels.to_vec(), per_label)?)
    }
}

/// The split of trial `trial`: per label, disjoint training, validation and test frames, each
/// contact's frames in one part (`sizes` count contacts; a frame without a contact is one).
pub fn trial_split(
    kept: &[RealReading],
    sizes: SplitSizes,
    seed: u64,
    trial: usize,
) -> Result<Split<&RealReading>, BoxError> {
    let trial_seed = trial_seed(seed, trial);
    let split = split_per_label(contacts_of(kept), |c| c[0].label.as_str(), sizes, trial_seed)?;
    Ok(Split {
        train: split.train.concat(),
        validation: split.validation.concat(),
        test: split.test.concat(),
    })
}

/// The seed of trial `trial`'s split (also the `stream_seed` column of its rows).
fn trial_seed(seed: u64, trial: usize) -> u64 {
    rng::substream(rng::substream(seed, SPLIT_STREAM), trial as u64)
}

/// One frame's features after the optional preprocessing.
fn describe_frame(
    descriptor: &dyn Descriptor,
    image: &TactileImage,
    options: &RealFramesOptions,
    blur: &GaussianBlur,
) -> Vec<Vec<f64>> {
    descriptor.describe(&preprocess(image, options, blur))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_sizes_follow_the_papers_proportions_when_scaled_down() {
        assert_eq!(scaled_split_sizes(384, 1.0), Ok(SplitSizes::PAPER));
        let s = scaled_split_sizes(8, 1.0).unwrap();
        assert_eq!((s.train, s.validation, s.test), (5, 1, 2));
        let s = scaled_split_sizes(384, 0.1).unwrap();
        assert_eq!((s.train, s.validation, s.test), (20, 5, 10));
        let s = scaled_split_sizes(100, 0.001).unwrap();
        assert_eq!((s.train, s.validation, s.test), (4, 1, 2));
        assert!(scaled_split_sizes(2, 1.0).is_err());
    }

    #[test]
    fn bad_options_name_their_flag() {
        let bad = RealFramesOptions {
            contact_threshold: 1.5,
            ..RealFramesOptions::default()
        };
        assert!(
            bad.check()
                .unwrap_err()
                .to_string()
                .contains("--contact-threshold")
        );
        let bad = RealFramesOptions {
            blur_sigma_taxels: -1.0,
            ..RealFramesOptions::default()
        };
        assert!(bad.check().unwrap_err().to_string().contains("--blur-sigma"));
    }
}
