//! Bag-of-features recognition (Sec. IV-A, V-B1; Fig. 4).
//!
//! Training: descriptor features of every training image -> [`Pca`](pipeline::Pca) keeping 90% of the variance ->
//! a [`Codebook`](pipeline::Codebook) (k-means, hard membership, or a Gaussian mixture, soft membership; beyond the
//! paper, [`NearestNeighbours`](pipeline::NearestNeighbours), the objects' shares of a feature's nearest training features, and [`FrameClassifier`](pipeline::FrameClassifier), a
//! network's posterior over the objects that several frames combine by the product rule) -> per object
//! the smoothed histogram `p(c_i | O_j)` ([`ObjectModels`](pipeline::ObjectModels)); [`train`] repeats the codebook step
//! over a grid of `k` and seeded restarts and keeps the best on validation data.
//!
//! Testing: the features of the unknown object's readings go through the same PCA and codebook
//! into a histogram `p(c_i | U)`; the guess minimises the cross-entropy of Eq. 4, and the
//! distribution over objects is the softmax of `n_U` times the average log-likelihood (Eq. 16).
//! [`OnlinePosterior`] does this after every reading ([`ModelPosterior`], from
//! [`TrainedModel::posterior`], takes tactile images); [`evaluate()`] (and
//! [`TrainedModel::evaluate`]) over a whole test set.
//!
//! Everything here works on features (`Vec<Feature>` per reading), so it knows nothing of MuJoCo:
//! recorded data from a real sensor can be fed in. A [`TrainedModel`] adds the descriptor, the
//! sensor configuration and persistence.

pub(crate) mod bag;
pub(crate) mod calibration;
pub(crate) mod codebook;
pub(crate) mod confusion;
pub(crate) mod decision;
pub(crate) mod error;
pub(crate) mod evaluate;
pub(crate) mod exp;
pub(crate) mod features;
pub(crate) mod fusion;
pub(crate) mod geometric;
pub(crate) mod gmm;
pub(crate) mod gmm_products;
pub(crate) mod kmeans;
pub(crate) mod labelled;
pub(crate) mod mlp;
pub(crate) mod model;
pub(crate) mod neighbours;
pub(crate) mod object_model;
pub(crate) mod pca;
pub(crate) mod posterior;
pub(crate) mod recognizer;
pub(crate) mod reliability;
pub(crate) mod request;
pub(crate) mod selection;
pub(crate) mod trial;

// The model: trained, saved and loaded, one descriptor or several fused.
pub use bag::BagOfFeatures;
pub use error::RecognizeError;
pub use fusion::{DescriptorChoice, DescriptorChoiceError, FusedModel};
pub use geometric::{AloneTemperings, Appearance, Evidence, GeometricFusion, Weighing};
pub use labelled::LabelledFeatures;
pub use model::{
    MODEL_FORMAT_VERSION, TrainedModel, TrainingProvenance, check_same_sensor, sensor_differences,
};
pub use posterior::{GeometricPosterior, TouchReading};
pub use recognizer::Recognizer;
// The one training entry of the CLI and Python: a user's choices, the data, the recogniser.
pub use request::{TrainChoices, TrainData, TrainObserver, check_contacts_weighable, train_recognizer};

// Its parameters, checked (`Valid<TrainConfig>`) before anything is fitted, and model selection.
pub use codebook::{CodebookConfig, CodebookKind};
pub use object_model::{EvidenceRule, PseudoCount};
pub use pca::VarianceFraction;
pub use selection::{
    CandidateScore, MIN_FEATURES_PER_CLUSTER, SelectionReport, TrainConfig, TrainProgress, Trained,
    codebook_sizes, supported_codebook_sizes, train,
};

// The posterior over objects, touch by touch (Eq. 15-16), calibrated by a fitted tempering.
pub use calibration::{ConfidenceMap, EvidencePath, PosteriorRule, Tempering};
pub use decision::{Decision, cross_entropy, entropy_nats};
pub use posterior::{Belief, FusedPosterior, ModelPosterior, OnlinePosterior};

// Evaluation over a test set (Sec. V-B2).
pub use confusion::ConfusionMatrix;
pub use evaluate::{
    AccuracyPoint, Evaluation, ReadingRange, TouchRow, TrialOutcome, evaluate, evaluate_with,
};
pub use trial::{Trial, make_trials};
// Calibration: whether the top probability can be trusted (ECE, reliability table).
pub use reliability::{CONFIDENCE_BINS, ReliabilityBin, ReliabilityTable};

/// The stages of Fig. 4 one by one, for code that fits or inspects them on their own (the tests,
/// the benchmarks, the parity checks against scikit-learn): features as a matrix, the PCA, the
/// codebooks (k-means, Gaussian mixture, nearest neighbours) and the object histograms.
/// [`train`] and [`TrainedModel::fit`] run them all.
pub mod pipeline {
    pub use super::codebook::{Codebook, CodebookModel};
    pub use super::features::{FeatureMatrix, TrainingFeatures};
    pub use super::gmm::{GaussianMixture, GmmConfig, GmmFit, GmmParameters};
    pub use super::kmeans::{KMeans, KMeansConfig, KMeansFit, kmeans_plus_plus};
    pub use super::mlp::{FrameClassifier, MlpConfig};
    pub use super::neighbours::{LeaveOneReadingOut, NearestNeighbours};
    pub use super::object_model::{ClusterHistogram, ObjectModelParameters, ObjectModels};
    pub use super::pca::Pca;
}
