//! What can go wrong in training, recognising, and loading a model.

use crate::tactile::SensorConfig;

/// Errors of the recognition module; each names the file, field or object involved.
#[derive(Debug, thiserror::Error)]
pub enum RecognizeError {
    #[error("no training features: {0}")]
    NoFeatures(String),
    #[error("feature {index} of {origin} has {got} values, expected {expected}")]
    FeatureDimension {
        origin: String,
        index: usize,
        got: usize,
        expected: usize,
    },
    #[error("feature {index} of {origin}: value {position} is {value}, features must be finite")]
    NonFiniteFeature {
        origin: String,
        index: usize,
        position: usize,
        value: f64,
    },
    #[error("invalid parameter {name}: {what}")]
    InvalidParameter { name: &'static str, what: String },
    #[error("the training features have zero variance: every feature is the same, nothing to recognise by")]
    ZeroVariance,
    #[error("{k} clusters need at least {k} training features, got {n}")]
    TooFewFeatures { k: usize, n: usize },
    #[error(
        "Gaussian mixture component {component} has a covariance that is not positive definite \
         (increase reg_covar or reduce k)"
    )]
    SingularCovariance { component: usize },
    #[error("object '{object}' has no training readings")]
    EmptyObject { object: String },
    #[error("object '{object}' is not one of the model's objects ({})", known.join(", "))]
    UnknownObject { object: String, known: Vec<String> },
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: truncated model file ({what})")]
    Truncated { path: String, what: String },
    #[error("{path}: model format version {found}, but this build reads version {expected}")]
    Version { path: String, found: u64, expected: u32 },
    #[error("{path}: not a taction model: {what}")]
    NotAModel { path: String, what: String },
    #[error("{path}: inconsistent model: {what}")]
    Inconsistent { path: String, what: String },
    #[error("the model was trained with a different sensor: {differences}")]
    SensorMismatch {
        differences: String,
        model: Box<SensorConfig>,
        data: Box<SensorConfig>,
    },
    #[error("{0}")]
    Dataset(#[from] crate::dataset::DatasetError),
    /// Fitting the posterior on the calibration explorations failed; the edges name the files.
    #[error("calibration: {0}")]
    Calibration(Box<RecognizeError>),
}

impl From<crate::atomic::FileError> for RecognizeError {
    fn from(e: crate::atomic::FileError) -> Self {
        Self::Io {
            path: e.path.display().to_string(),
            source: e.source,
        }
    }
}
