//! Bag-of-features recognition (Sec. IV-A, V-B1; Fig. 4).
//!
//! Training: descriptor features of every training image -> [`Pca`] keeping 90% of the variance ->
//! a [`Codebook`] (k-means, hard membership, or a Gaussian mixture, soft membership; beyond the
//! paper, [`NearestNeighbours`], the objects' shares of a feature's nearest training features) -> per object
//! the smoothed histogram `p(c_i | O_j)` ([`ObjectModels`]); [`train`] repeats the codebook step
//! over a grid of `k` and seeded restarts and keeps the best on validation data.
//!
//! Testing: the features of the unknown object's readings go through the same PCA and codebook
//! into a histogram `p(c_i | U)`; the guess minimises the cross-entropy of Eq. 4, and the
//! distribution over objects is the softmax of `n_U` times the average log-likelihood (Eq. 16).
//! [`OnlinePosterior`] does this after every reading; [`evaluate()`] over a whole test set.
//!
//! Everything here works on features (`Vec<Feature>` per reading), so it knows nothing of MuJoCo:
//! recorded data from a real sensor can be fed in. A [`TrainedModel`] adds the descriptor, the
//! sensor configuration and persistence.

pub(crate) mod bag;
pub(crate) mod codebook;
pub(crate) mod confusion;
pub(crate) mod decision;
pub(crate) mod error;
pub mod evaluate;
pub(crate) mod features;
pub(crate) mod fusion;
pub(crate) mod gmm;
pub(crate) mod kmeans;
pub(crate) mod labelled;
pub mod model;
pub(crate) mod neighbours;
pub(crate) mod object_model;
pub(crate) mod pca;
pub(crate) mod posterior;
pub mod selection;

pub use bag::BagOfFeatures;
pub use codebook::{Codebook, CodebookConfig, CodebookKind, CodebookModel};
pub use confusion::ConfusionMatrix;
pub use decision::{Decision, cross_entropy, entropy_nats};
pub use error::RecognizeError;
pub use evaluate::{
    AccuracyPoint, Evaluation, ReadingRange, TouchRow, Trial, evaluate, evaluate_with, make_trials,
};
pub use features::{FeatureMatrix, TrainingFeatures};
pub use fusion::{DescriptorChoice, DescriptorChoiceError, FusedModel, FusedPosterior, Recognizer};
pub use gmm::{GaussianMixture, GmmConfig, GmmFit, GmmParameters};
pub use kmeans::{KMeans, KMeansConfig, KMeansFit, kmeans_plus_plus};
pub use labelled::LabelledFeatures;
pub use model::{MODEL_FORMAT_VERSION, TrainedModel, TrainingProvenance, check_same_sensor};
pub use neighbours::{LeaveOneReadingOut, NearestNeighbours};
pub use object_model::{ClusterHistogram, ObjectModelParameters, ObjectModels, PseudoCount};
pub use pca::{Pca, VarianceFraction};
pub use posterior::{Belief, OnlinePosterior};
pub use selection::{
    CandidateScore, SelectionReport, TrainConfig, TrainProgress, Trained, codebook_sizes,
    supported_codebook_sizes, train,
};
