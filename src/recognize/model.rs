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
use crate::recognize::labelled::LabelledFeatures;
use crate::recognize::selection::{SelectionReport, TrainConfig, TrainProgress, train};
use crate::tactile::{SensorConfig, TactileImage};

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
    /// candidates of `config` on `validation` (or on readings held out of `training`), and records
    /// the sensor and provenance of the data. The one training path of the CLI, the demo and the
    /// experiments.
    pub fn fit(
        training: &Dataset,
        validation: Option<&Dataset>,
        descriptor: &dyn Descriptor,
        config: TrainConfig,
        progress: &mut (dyn FnMut(TrainProgress) + Send),
    ) -> Result<Self, RecognizeError> {
        let header = training.header();
        if let Some(v) = validation {
            check_same_sensor(&header.sensor, &v.header().sensor)?;
        }
        let train_features = LabelledFeatures::from_dataset(training, descriptor);
        let validation_features = validation.map(|v| LabelledFeatures::from_dataset(v, descriptor));
        let trained = train(&train_features, validation_features.as_ref(), &config, progress)?;
        Ok(Self::new(
            descriptor.params(),
            header.sensor,
            trained.bag,
            trained.selection,
            TrainingProvenance {
                object_set: header.object_set.clone(),
                generator: header.generator.clone(),
                dataset_seed: header.seed,
                config,
            },
        ))
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
        let path = || origin.to_string();
        let value: serde_json::Value = serde_json::from_slice(bytes).map_err(|e| {
            if e.is_eof() {
                RecognizeError::Truncated {
                    path: path(),
                    what: format!("the JSON ends early: {e}"),
                }
            } else {
                RecognizeError::NotAModel {
                    path: path(),
                    what: format!("not JSON: {e}"),
                }
            }
        })?;
        let version = value
            .get("format_version")
            .ok_or_else(|| RecognizeError::NotAModel {
                path: path(),
                what: "no 'format_version' field".into(),
            })?;
        match version.as_u64() {
            Some(v) if v == u64::from(MODEL_FORMAT_VERSION) => {}
            Some(found) => {
                return Err(RecognizeError::Version {
                    path: path(),
                    found,
                    expected: MODEL_FORMAT_VERSION,
                });
            }
            None => {
                return Err(RecognizeError::NotAModel {
                    path: path(),
                    what: format!("'format_version' is {version}, not an unsigned integer"),
                });
            }
        }
        let model: TrainedModel =
            serde_json::from_value(value).map_err(|e| RecognizeError::Inconsistent {
                path: path(),
                what: e.to_string(),
            })?;
        model
            .bag
            .check()
            .map_err(|what| RecognizeError::Inconsistent { path: path(), what })?;
        let descriptor = model
            .descriptor
            .build()
            .map_err(|e| RecognizeError::Inconsistent {
                path: path(),
                what: format!(
                    "the descriptor parameters {:?} are invalid: {e}",
                    model.descriptor
                ),
            })?;
        // What the descriptor gives for an image of the model's sensor must be what the PCA takes.
        let blank = TactileImage::zeros(model.sensor.rows, model.sensor.cols).map_err(|e| {
            RecognizeError::Inconsistent {
                path: path(),
                what: format!("sensor: {e}"),
            }
        })?;
        let produced = descriptor.describe(&blank).first().map_or(0, Vec::len);
        if produced != model.bag.input_dim() {
            return Err(RecognizeError::Inconsistent {
                path: path(),
                what: format!(
                    "{} gives {produced} values for a {}x{} image, but the PCA takes {}",
                    model.descriptor.kind().name(),
                    model.sensor.rows,
                    model.sensor.cols,
                    model.bag.input_dim()
                ),
            });
        }
        Ok(model)
    }
}

/// Checks that data taken with sensor `data` can be recognised by a model trained on `model`:
/// every field must be equal except `noise_seed` (another noise stream of the same noise level is
/// the same sensor). The error lists each differing field.
pub fn check_same_sensor(model: &SensorConfig, data: &SensorConfig) -> Result<(), RecognizeError> {
    let (m, d) = (model, data);
    if *m
        == (SensorConfig {
            noise_seed: m.noise_seed,
            ..*d
        })
    {
        return Ok(());
    }
    let mut differences = Vec::new();
    let mut differ = |name: &str, a: String, b: String| {
        if a != b {
            differences.push(format!("{name} {a} (model) vs {b} (data)"));
        }
    };
    differ("rows", m.rows.to_string(), d.rows.to_string());
    differ("cols", m.cols.to_string(), d.cols.to_string());
    differ(
        "pad_width_m",
        m.pad_width_m.to_string(),
        d.pad_width_m.to_string(),
    );
    differ(
        "pad_height_m",
        m.pad_height_m.to_string(),
        d.pad_height_m.to_string(),
    );
    differ(
        "thickness_m",
        m.thickness_m.to_string(),
        d.thickness_m.to_string(),
    );
    differ(
        "psf_sigma_m",
        m.psf_sigma_m.to_string(),
        d.psf_sigma_m.to_string(),
    );
    differ(
        "rays_per_taxel",
        m.rays_per_taxel.to_string(),
        d.rays_per_taxel.to_string(),
    );
    differ(
        "noise_fraction",
        m.noise_fraction.to_string(),
        d.noise_fraction.to_string(),
    );
    if differences.is_empty() {
        differences.push("a field differs".into());
    }
    Err(RecognizeError::SensorMismatch {
        differences: differences.join(", "),
        model: Box::new(*m),
        data: Box::new(*d),
    })
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
pub(crate) fn save_json<T: serde::Serialize>(value: &T, path: &Path) -> Result<(), RecognizeError> {
    let json = serde_json::to_vec(value).map_err(|e| RecognizeError::NotAModel {
        path: path.display().to_string(),
        what: format!("cannot encode: {e}"),
    })?;
    write_atomic(path, &json)?;
    Ok(())
}
