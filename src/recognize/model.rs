//! A trained model on disk: everything needed to recognise new readings exactly as training saw
//! them: the descriptor with its parameters, the PCA, the codebook, the object histograms, the
//! sensor the training data came from, and how the model was chosen.
//!
//! The file is JSON (`serde_json` with its `float_roundtrip` feature: floats are written in
//! shortest round-trip form and parsed exactly, so save -> load is bit-exact), written atomically. Loading checks, in order: the file can be read; it is complete
//! JSON (else [`Truncated`](RecognizeError::Truncated)); it has this build's `format_version`
//! (else [`Version`](RecognizeError::Version)); every part deserialises and the parts agree in
//! their dimensions (else [`Inconsistent`](RecognizeError::Inconsistent)).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::atomic::write_atomic;
use crate::dataset::Dataset;
use crate::describe::{Descriptor, DescriptorParams};
use crate::recognize::RecognizeError;
use crate::recognize::bag::BagOfFeatures;
use crate::recognize::calibration::{EvidencePath, PosteriorRule, Tempering};
use crate::recognize::evaluate::{Evaluation, ReadingRange, evaluate};
use crate::recognize::labelled::LabelledFeatures;
use crate::recognize::posterior::ModelPosterior;
use crate::recognize::selection::{SelectionReport, TrainConfig, TrainProgress, train};
use crate::recognize::trial::{Trial, make_trials};
use crate::tactile::{SensorConfig, TactileImage};
use crate::valid::Valid;

/// The model file format version this build writes and reads.
pub const MODEL_FORMAT_VERSION: u32 = 1;

/// Where the training data came from (for the record; not used to recognise).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainingProvenance {
    pub object_set: String,
    pub generator: String,
    pub dataset_seed: u64,
    pub config: TrainConfig,
}

/// A trained bag-of-features recogniser with the context it is valid in.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainedModel {
    pub format_version: u32,
    /// The descriptor and its parameters: test images must be described the same way.
    pub descriptor: DescriptorParams,
    /// The sensor of the training data; test data must match it (see [`check_sensor`](Self::check_sensor)).
    pub sensor: SensorConfig,
    pub bag: BagOfFeatures,
    pub selection: SelectionReport,
    pub provenance: TrainingProvenance,
}

impl TrainedModel {
    /// A model of the current format version.
    pub fn new(
        descriptor: DescriptorParams,
        sensor: SensorConfig,
        bag: BagOfFeatures,
        selection: SelectionReport,
        provenance: TrainingProvenance,
    ) -> Self {
        Self {
            format_version: MODEL_FORMAT_VERSION,
            descriptor,
            sensor,
            bag,
            selection,
            provenance,
        }
    }

    /// Trains a model on the converged readings of `training` (Fig. 4), choosing among the
    /// candidates of the checked `config` on `validation` (or on readings held out of `training`),
    /// and records the sensor and provenance of the data: linfa's params -> check -> fit, and the
    /// one training path of the CLI, the demo and the experiments.
    ///
    /// # Example
    ///
    /// Two objects read by a 4x4 pad: an edge (the left half pressed harder) and a flat face, with
    /// a little texture. The model trained on them recognises new readings, image by image
    /// ([`posterior`](Self::posterior)) or a whole test set ([`evaluate`](Self::evaluate)).
    ///
    /// ```
    /// use taction::dataset::{ContactStatus, Dataset, DatasetHeader, Reading, Strategy};
    /// use taction::describe::DescriptorKind;
    /// use taction::pose::Pose;
    /// use taction::recognize::{ReadingRange, TrainConfig, TrainedModel};
    /// use taction::tactile::{SensorConfig, TactileImage};
    /// use taction::valid::Valid;
    ///
    /// let image = |object: usize, i: usize| {
    ///     let value = |t: usize| {
    ///         let texture = 0.05 * ((i * 7 + t * 3) % 5) as f64;
    ///         if object == 0 && t % 4 < 2 { 0.8 + texture } else { 0.3 + texture }
    ///     };
    ///     TactileImage::new(4, 4, (0..16).map(value).collect())
    /// };
    /// let objects = ["edge".to_string(), "face".to_string()];
    /// let dataset = |first: usize, per_object: usize| -> Result<Dataset, Box<dyn std::error::Error>> {
    ///     let sensor = SensorConfig::square(4, 4, 0.012, 0.0012);
    ///     let header = DatasetHeader::new(sensor, "toy", objects.to_vec(), "by hand", 0);
    ///     let mut readings = Vec::new();
    ///     for i in first..first + per_object {
    ///         for (j, object) in objects.iter().enumerate() {
    ///             readings.push(Reading {
    ///                 image: image(j, i)?,
    ///                 object: object.clone(),
    ///                 object_pose: Pose::IDENTITY,
    ///                 object_pose_after: None,
    ///                 status: ContactStatus::Converged,
    ///                 iterations: 1,
    ///                 strategy: Strategy::Sampler,
    ///                 cause: None,
    ///                 contact: None,
    ///             });
    ///         }
    ///     }
    ///     Ok(Dataset::new(header, readings)?)
    /// };
    ///
    /// let config = Valid::new(TrainConfig { ks: vec![2], restarts: 1, ..TrainConfig::default() })?;
    /// let descriptor = DescriptorKind::Vectorize.build();
    /// let model = TrainedModel::fit(&config, &dataset(0, 22)?, None, descriptor.as_ref(), &mut |_| {})?;
    ///
    /// let mut posterior = model.posterior()?;
    /// posterior.observe(&image(0, 100)?)?;
    /// let belief = posterior.observe(&image(0, 101)?)?;
    /// assert_eq!(model.bag.objects()[belief.guess()], "edge");
    /// assert_eq!(posterior.probabilities().len(), 2);
    ///
    /// let evaluation = model.evaluate(&dataset(50, 5)?, ReadingRange::new(1, 5)?)?;
    /// assert_eq!(evaluation.accuracy_at(5), Some(1.0));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn fit(
        config: &Valid<TrainConfig>,
        training: &Dataset,
        validation: Option<&Dataset>,
        descriptor: &dyn Descriptor,
        progress: &mut (dyn FnMut(TrainProgress) + Send),
    ) -> Result<Self, RecognizeError> {
        let header = training.header();
        if let Some(v) = validation {
            check_same_sensor(&header.sensor, &v.header().sensor)?;
        }
        let train_features = LabelledFeatures::from_dataset(training, descriptor);
        let validation_features = validation.map(|v| LabelledFeatures::from_dataset(v, descriptor));
        let trained = train(config, &train_features, validation_features.as_ref(), progress)?;
        Ok(Self::new(
            descriptor.params(),
            header.sensor,
            trained.bag,
            trained.selection,
            TrainingProvenance {
                object_set: header.object_set.clone(),
                generator: header.generator.clone(),
                dataset_seed: header.seed,
                config: TrainConfig::clone(config),
            },
        ))
    }

    /// The same model with the posterior `rule` applies: the tempering fitted on validation
    /// (the default) or the paper's Eq. 15 (`--posterior eq15`).
    pub fn with_posterior(self, rule: PosteriorRule) -> Self {
        Self {
            bag: self.bag.with_posterior(rule),
            ..self
        }
    }

    /// A posterior over the model's objects (Eq. 15-16) that takes tactile images one at a time,
    /// describing each with the model's descriptor ([`ModelPosterior::observe`]), or readings
    /// already described ([`ModelPosterior::observe_features`]). The example of
    /// [`fit`](Self::fit) uses it.
    pub fn posterior(&self) -> Result<ModelPosterior<'_>, RecognizeError> {
        Ok(ModelPosterior::single(&self.bag, self.build_descriptor()?))
    }

    /// Recognition touch by touch over the converged readings of `test` (Sec. V-B2): each object's
    /// readings, in order, in trials of `readings.last()` readings, the belief recorded at every
    /// reading count of `readings`; accuracy as [`AccuracyPoint`](crate::recognize::AccuracyPoint)
    /// defines it. `test` must come from the model's sensor and name only its objects. The example
    /// of [`fit`](Self::fit) uses it.
    pub fn evaluate(&self, test: &Dataset, readings: ReadingRange) -> Result<Evaluation, RecognizeError> {
        Ok(self.evaluate_counted(test, readings)?.0)
    }

    /// [`evaluate`](Self::evaluate), and the number of trials.
    pub(crate) fn evaluate_counted(
        &self,
        test: &Dataset,
        readings: ReadingRange,
    ) -> Result<(Evaluation, usize), RecognizeError> {
        let trials = self.trials(test, readings.last())?;
        Ok((evaluate(&self.bag, &trials, readings)?, trials.len()))
    }

    /// The converged readings of `test`, described by the model's descriptor, as trials of up to
    /// `readings_per_trial` readings ([`make_trials`]).
    pub fn trials(&self, test: &Dataset, readings_per_trial: usize) -> Result<Vec<Trial>, RecognizeError> {
        self.check_sensor(&test.header().sensor)?;
        let descriptor = self.build_descriptor()?;
        let features = LabelledFeatures::from_dataset(test, descriptor.as_ref());
        make_trials(&features, self.bag.objects(), readings_per_trial)
    }

    /// The same model with its posterior's tempering fitted again, on the converged readings of
    /// `data` in trials of `trial_readings` (`recognize::calibration`): calibration data of the
    /// kind the model will be judged on (the arm's own explorations, whose successive touches are
    /// correlated) rather than the validation readings it was chosen on (`taction train
    /// --calibration`). `trial_readings` should be the length of the runs the model will
    /// recognise (`usize::MAX`: each object's readings as one trial), since the tempering is only
    /// fitted at the reading counts the trials reach.
    pub fn calibrate_on(self, data: &Dataset, trial_readings: usize) -> Result<Self, RecognizeError> {
        self.calibrate_on_all(&[data], trial_readings)
    }

    /// [`calibrate_on`](Self::calibrate_on) the trials of every dataset of `data` together (several
    /// explorations of each object: more paths to fit the tempering on).
    pub fn calibrate_on_all(self, data: &[&Dataset], trial_readings: usize) -> Result<Self, RecognizeError> {
        let mut trials = Vec::new();
        for dataset in data {
            trials.extend(self.trials(dataset, trial_readings)?);
        }
        let paths = trials
            .iter()
            .map(|trial| {
                let mut posterior = self.bag.posterior();
                EvidencePath::of(trial, |reading| {
                    posterior.observe(reading)?;
                    Ok(self.bag.models().log_likelihoods(posterior.histogram()))
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            bag: self
                .bag
                .with_tempering(Tempering::fit_with_confidence_map(&paths)),
            ..self
        })
    }

    /// Builds the descriptor the model was trained with.
    pub fn build_descriptor(&self) -> Result<Box<dyn Descriptor>, RecognizeError> {
        self.descriptor
            .build()
            .map_err(|e| RecognizeError::InvalidParameter {
                name: "descriptor",
                what: e.to_string(),
            })
    }

    /// Checks that data taken with `data` can be recognised by this model ([`check_same_sensor`]).
    pub fn check_sensor(&self, data: &SensorConfig) -> Result<(), RecognizeError> {
        check_same_sensor(&self.sensor, data)
    }

    /// Writes the model as JSON, atomically.
    pub fn save(&self, path: &Path) -> Result<(), RecognizeError> {
        save_json(self, path)
    }

    /// Reads a model written by [`save`](Self::save); see the module docs for the checks.
    pub fn load(path: &Path) -> Result<Self, RecognizeError> {
        let (bytes, name) = read_model_file(path)?;
        Self::from_json(&bytes, &name)
    }

    /// Parses the bytes of a model file; `origin` names it in errors.
    pub fn from_json(bytes: &[u8], origin: &str) -> Result<Self, RecognizeError> {
        let value = parse_model_json(bytes, origin)?;
        check_format_version(&value, origin)?;
        let model: TrainedModel =
            serde_json::from_value(value).map_err(|e| RecognizeError::Inconsistent {
                path: origin.to_string(),
                what: e.to_string(),
            })?;
        model
            .check_parts_agree()
            .map_err(|what| RecognizeError::Inconsistent {
                path: origin.to_string(),
                what,
            })?;
        Ok(model)
    }

    /// The parts of a loaded model agree: the bag's own dimensions, the descriptor parameters, and
    /// what the descriptor gives for an image of the model's sensor is what the PCA takes.
    fn check_parts_agree(&self) -> Result<(), String> {
        self.bag.check()?;
        let descriptor = self
            .descriptor
            .build()
            .map_err(|e| format!("the descriptor parameters {:?} are invalid: {e}", self.descriptor))?;
        let blank =
            TactileImage::zeros(self.sensor.rows, self.sensor.cols).map_err(|e| format!("sensor: {e}"))?;
        let produced = descriptor.describe(&blank).first().map_or(0, Vec::len);
        if produced != self.bag.input_dim() {
            return Err(format!(
                "{} gives {produced} values for a {}x{} image, but the PCA takes {}",
                self.descriptor.kind().name(),
                self.sensor.rows,
                self.sensor.cols,
                self.bag.input_dim()
            ));
        }
        Ok(())
    }
}

/// The JSON of a model file: a file cut short is [`Truncated`](RecognizeError::Truncated), anything
/// else that is not JSON [`NotAModel`](RecognizeError::NotAModel).
fn parse_model_json(bytes: &[u8], origin: &str) -> Result<serde_json::Value, RecognizeError> {
    serde_json::from_slice(bytes).map_err(|e| {
        if e.is_eof() {
            RecognizeError::Truncated {
                path: origin.to_string(),
                what: format!("the JSON ends early: {e}"),
            }
        } else {
            RecognizeError::NotAModel {
                path: origin.to_string(),
                what: format!("not JSON: {e}"),
            }
        }
    })
}

/// The file's `format_version` is this build's [`MODEL_FORMAT_VERSION`].
fn check_format_version(value: &serde_json::Value, origin: &str) -> Result<(), RecognizeError> {
    let path = || origin.to_string();
    let version = value
        .get("format_version")
        .ok_or_else(|| RecognizeError::NotAModel {
            path: path(),
            what: "no 'format_version' field".into(),
        })?;
    match version.as_u64() {
        Some(v) if v == u64::from(MODEL_FORMAT_VERSION) => Ok(()),
        Some(found) => Err(RecognizeError::Version {
            path: path(),
            found,
            expected: MODEL_FORMAT_VERSION,
        }),
        None => Err(RecognizeError::NotAModel {
            path: path(),
            what: format!("'format_version' is {version}, not an unsigned integer"),
        }),
    }
}

/// Checks that data taken with sensor `data` can be recognised by a model trained on `model`:
/// every field must be equal except `noise_seed` (another noise stream of the same noise level is
/// the same sensor). The error lists each differing field.
pub fn check_same_sensor(model: &SensorConfig, data: &SensorConfig) -> Result<(), RecognizeError> {
    match sensor_differences((model, "model"), (data, "data")) {
        None => Ok(()),
        Some(differences) => Err(RecognizeError::SensorMismatch {
            differences,
            model: Box::new(*model),
            data: Box::new(*data),
        }),
    }
}

/// The fields in which two sensors differ in what changes their readings, each as
/// `name A (a) vs B (b)` with the two sides' labels; `None` when they read alike. Lengths and
/// fractions are the same within a relative 1e-9: a covering of 0.0012 m and one worked out as a
/// tenth of 0.012 m (0.0012000000000000001) are one sensor. `noise_seed` never counts: it draws the
/// noise, which a model does not learn sample by sample.
pub fn sensor_differences(
    (a, a_label): (&SensorConfig, &str),
    (b, b_label): (&SensorConfig, &str),
) -> Option<String> {
    let SensorConfig {
        rows,
        cols,
        pad_width_m,
        pad_height_m,
        thickness_m,
        psf_sigma_m,
        rays_per_taxel,
        noise_fraction,
        noise_seed: _,
    } = *a;
    let count =
        |name: &'static str, x: usize, y: usize| (x != y).then(|| (name, x.to_string(), y.to_string()));
    let real = |name: &'static str, x: f64, y: f64| {
        let same = x == y || (x - y).abs() <= 1e-9 * x.abs().max(y.abs());
        (!same).then(|| (name, x.to_string(), y.to_string()))
    };
    let differences: Vec<String> = [
        count("rows", rows, b.rows),
        count("cols", cols, b.cols),
        real("pad_width_m", pad_width_m, b.pad_width_m),
        real("pad_height_m", pad_height_m, b.pad_height_m),
        real("thickness_m", thickness_m, b.thickness_m),
        real("psf_sigma_m", psf_sigma_m, b.psf_sigma_m),
        count("rays_per_taxel", rays_per_taxel, b.rays_per_taxel),
        real("noise_fraction", noise_fraction, b.noise_fraction),
    ]
    .into_iter()
    .flatten()
    .map(|(name, x, y)| format!("{name} {x} ({a_label}) vs {y} ({b_label})"))
    .collect();
    (!differences.is_empty()).then(|| differences.join(", "))
}

/// The bytes of a model file and its name for error messages.
pub(crate) fn read_model_file(path: &Path) -> Result<(Vec<u8>, String), RecognizeError> {
    let name = path.display().to_string();
    match std::fs::read(path) {
        Ok(bytes) => Ok((bytes, name)),
        Err(source) => Err(RecognizeError::Io { path: name, source }),
    }
}

/// Writes a model file (`value` as JSON) atomically: a reader never sees half of it.
/// A model file's contents; `origin` names the destination in errors.
pub(crate) fn encode_json<T: serde::Serialize>(value: &T, origin: &str) -> Result<Vec<u8>, RecognizeError> {
    serde_json::to_vec(value).map_err(|e| RecognizeError::NotAModel {
        path: origin.to_string(),
        what: format!("cannot encode: {e}"),
    })
}

pub(crate) fn save_json<T: serde::Serialize>(value: &T, path: &Path) -> Result<(), RecognizeError> {
    let json = encode_json(value, &path.display().to_string())?;
    write_atomic(path, &json)?;
    Ok(())
}

/// The model file's `format_version` is this build's.
pub(crate) fn check_version(value: &serde_json::Value, origin: &str) -> Result<(), RecognizeError> {
    match value.get("format_version").and_then(serde_json::Value::as_u64) {
        Some(v) if v == u64::from(MODEL_FORMAT_VERSION) => Ok(()),
        Some(found) => Err(RecognizeError::Version {
            path: origin.to_string(),
            found,
            expected: MODEL_FORMAT_VERSION,
        }),
        None => Err(RecognizeError::NotAModel {
            path: origin.to_string(),
            what: "no unsigned 'format_version' field".into(),
        }),
    }
}
