//! The learned clustering function `C(f)` of Sec. IV-A, as a membership over clusters that applies
//! to new data after training (the requirement of Sec. V-B1).

use serde::{Deserialize, Serialize};

use crate::recognize::RecognizeError;
use crate::recognize::features::TrainingFeatures;
use crate::recognize::gmm::{GaussianMixture, GmmConfig};
use crate::recognize::kmeans::{KMeans, KMeansConfig};
use crate::recognize::mlp::{FrameClassifier, MlpConfig};
use crate::recognize::neighbours::NearestNeighbours;
use crate::recognize::object_model::EvidenceRule;
use crate::recognize::pca::{Pca, VarianceFraction};
use crate::rng::Rng;

/// A clustering function with a membership usable on new features.
pub trait Codebook: Send + Sync {
    /// Number of clusters `n_C`.
    fn clusters(&self) -> usize;
    /// Length of the (PCA-reduced) features it takes.
    fn dim(&self) -> usize;
    /// Writes `p(c_i | f)` for every cluster into `out` (length [`clusters`](Self::clusters)); the
    /// values are non-negative and sum to 1. Hard codebooks write a one-hot vector.
    fn membership(&self, f: &[f64], out: &mut [f64]);
}

impl Codebook for KMeans {
    fn clusters(&self) -> usize {
        self.k()
    }

    fn dim(&self) -> usize {
        KMeans::dim(self)
    }

    fn membership(&self, f: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        out[self.nearest(f)] = 1.0;
    }
}

impl Codebook for GaussianMixture {
    fn clusters(&self) -> usize {
        self.k()
    }

    fn dim(&self) -> usize {
        GaussianMixture::dim(self)
    }

    /// The component posterior `p(g_i | f) = p(f | g_i) p(g_i) / sum_m p(f | g_m) p(g_m)`.
    ///
    /// Eq. 11 as printed sums the joint densities `p(f | g_i) p(g_i)` over features and normalises
    /// once; we normalise per feature instead, so every feature adds a total weight of 1 to the
    /// histogram. That is what "soft binning" and the Appendix's `k_i = n_U p(c_i | U)` (a count of
    /// features) need: with raw densities, one feature in a dense region would outweigh many
    /// elsewhere, and `n_U` in Eq. 16 would no longer be the number of features.
    fn membership(&self, f: &[f64], out: &mut [f64]) {
        self.responsibilities(f, out);
    }
}

impl Codebook for NearestNeighbours {
    fn clusters(&self) -> usize {
        NearestNeighbours::clusters(self)
    }

    fn dim(&self) -> usize {
        NearestNeighbours::dim(self)
    }

    fn membership(&self, f: &[f64], out: &mut [f64]) {
        NearestNeighbours::membership(self, f, out)
    }
}

impl Codebook for FrameClassifier {
    fn clusters(&self) -> usize {
        FrameClassifier::clusters(self)
    }

    fn dim(&self) -> usize {
        FrameClassifier::dim(self)
    }

    fn membership(&self, f: &[f64], out: &mut [f64]) {
        FrameClassifier::membership(self, f, out)
    }
}

/// Which clustering method builds the codebook.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CodebookKind {
    /// Gaussian mixture, soft membership (the paper's better performer).
    Gmm,
    /// k-means with k-means++ seeding, hard membership.
    Kmeans,
    /// Beyond the paper: the training objects as clusters, a feature's membership the objects'
    /// shares of its `k` nearest training features ([`NearestNeighbours`]).
    Knn,
    /// Beyond the paper: the training objects as clusters, a feature's membership a trained
    /// network's posterior over them ([`FrameClassifier`]); readings combine by the product rule
    /// ([`EvidenceRule::PerFrame`]).
    Mlp,
}

impl CodebookKind {
    pub const ALL: [CodebookKind; 4] = [Self::Gmm, Self::Kmeans, Self::Knn, Self::Mlp];

    /// The command-line name: `gmm`, `kmeans`, `knn` or `mlp`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Gmm => "gmm",
            Self::Kmeans => "kmeans",
            Self::Knn => "knn",
            Self::Mlp => "mlp",
        }
    }

    /// The kind a command-line name names; else the message the CLI and Python give.
    pub fn parse(name: &str) -> Result<Self, String> {
        Self::from_name(name).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|k| k.name()).collect();
            format!("unknown codebook '{name}'; expected {}", names.join(", "))
        })
    }

    /// Whether fitting draws random numbers, so that seeded restarts can differ (the neighbour
    /// codebook is a function of the data).
    pub fn is_random(self) -> bool {
        !matches!(self, Self::Knn)
    }

    /// The fraction of the training variance the PCA keeps by default: the paper's 90% for the
    /// clustering codebooks; 99% for the neighbour codebook, whose neighbourhoods use the detail
    /// the last components keep (docs/measurements.md, "A neighbour codebook", has the
    /// measurement); all of it for the network, which reads the features back in the
    /// descriptor's units and learns which of them matter (99% cost it 3 points on the
    /// large-array benchmark).
    pub fn default_variance_kept(self) -> VarianceFraction {
        match self {
            Self::Gmm | Self::Kmeans => VarianceFraction::PAPER,
            Self::Knn => VarianceFraction::NEIGHBOURS,
            Self::Mlp => VarianceFraction::NETWORK,
        }
    }

    /// How the memberships of several features make the evidence for each object: Eq. 4's
    /// cross-entropy of their histogram, or, for a classifier's posterior, the product rule.
    pub fn evidence_rule(self) -> EvidenceRule {
        match self {
            Self::Gmm | Self::Kmeans | Self::Knn => EvidenceRule::CrossEntropy,
            Self::Mlp => EvidenceRule::PerFrame,
        }
    }

    /// Parses [`name`](Self::name).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// How codebooks are fitted.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct CodebookConfig {
    /// The k-means codebook's iterations.
    pub kmeans: KMeansConfig,
    /// EM settings, including the k-means run that initialises it.
    pub gmm: GmmConfig,
    /// The network's training; left out of a file at its default, so configurations written
    /// before the network existed read and compare the same.
    #[serde(default, skip_serializing_if = "MlpConfig::is_default")]
    pub mlp: MlpConfig,
}

/// A fitted codebook of any kind (what a saved model holds).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum CodebookModel {
    Kmeans(KMeans),
    Gmm(GaussianMixture),
    Knn(NearestNeighbours),
    Mlp(FrameClassifier),
}

impl CodebookModel {
    /// Fits a `kind` codebook of `k` clusters (`k` neighbours for [`CodebookKind::Knn`], `k` hidden
    /// units for [`CodebookKind::Mlp`]) on `training`, the output of `pca` (which the network
    /// reads back in the descriptor's units), drawing from `rng`.
    pub fn fit(
        kind: CodebookKind,
        training: TrainingFeatures,
        pca: &Pca,
        k: usize,
        config: &CodebookConfig,
        rng: &mut Rng,
    ) -> Result<Self, RecognizeError> {
        let data = training.data;
        Ok(match kind {
            CodebookKind::Kmeans => Self::Kmeans(KMeans::fit(data, k, &config.kmeans, rng)?.0),
            CodebookKind::Gmm => Self::Gmm(GaussianMixture::fit(data, k, &config.gmm, rng)?.0),
            CodebookKind::Knn => Self::Knn(NearestNeighbours::new(
                data,
                training.objects.to_vec(),
                training.object_count,
                k,
            )?),
            CodebookKind::Mlp => Self::Mlp(FrameClassifier::fit(training, pca, k, &config.mlp, rng)?),
        })
    }

    pub fn kind(&self) -> CodebookKind {
        match self {
            Self::Kmeans(_) => CodebookKind::Kmeans,
            Self::Gmm(_) => CodebookKind::Gmm,
            Self::Knn(_) => CodebookKind::Knn,
            Self::Mlp(_) => CodebookKind::Mlp,
        }
    }

    fn inner(&self) -> &dyn Codebook {
        match self {
            Self::Kmeans(k) => k,
            Self::Gmm(g) => g,
            Self::Knn(n) => n,
            Self::Mlp(m) => m,
        }
    }

    pub(crate) fn check(&self) -> Result<(), String> {
        match self {
            Self::Kmeans(k) => k.check(),
            // A GaussianMixture is validated when it is deserialised.
            Self::Gmm(_) => Ok(()),
            Self::Knn(n) => n.check(),
            Self::Mlp(m) => m.check(),
        }
    }
}

impl Codebook for CodebookModel {
    fn clusters(&self) -> usize {
        self.inner().clusters()
    }

    fn dim(&self) -> usize {
        self.inner().dim()
    }

    fn membership(&self, f: &[f64], out: &mut [f64]) {
        self.inner().membership(f, out)
    }
}
