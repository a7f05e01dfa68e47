//! The learned clustering function `C(f)` of Sec. IV-A, as a membership over clusters that applies
//! to new data after training (the requirement of Sec. V-B1).

use serde::{Deserialize, Serialize};

use crate::recognize::gmm::{GaussianMixture, GmmConfig};
use crate::recognize::kmeans::{KMeans, KMeansConfig};
use crate::recognize::{FeatureMatrix, RecognizeError};
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

/// Which clustering method builds the codebook.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CodebookKind {
    /// Gaussian mixture, soft membership (the paper's better performer).
    Gmm,
    /// k-means with k-means++ seeding, hard membership.
    Kmeans,
}

impl CodebookKind {
    pub const ALL: [CodebookKind; 2] = [Self::Gmm, Self::Kmeans];

    /// The command-line name: `gmm` or `kmeans`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Gmm => "gmm",
            Self::Kmeans => "kmeans",
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
}

/// A fitted codebook of either kind (what a saved model holds).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum CodebookModel {
    Kmeans(KMeans),
    Gmm(GaussianMixture),
}

impl CodebookModel {
    /// Fits a `kind` codebook of `k` clusters on `data`, drawing from `rng`.
    pub fn fit(
        kind: CodebookKind,
        data: &FeatureMatrix,
        k: usize,
        config: &CodebookConfig,
        rng: &mut Rng,
    ) -> Result<Self, RecognizeError> {
        Ok(match kind {
            CodebookKind::Kmeans => Self::Kmeans(KMeans::fit(data, k, &config.kmeans, rng)?.0),
            CodebookKind::Gmm => Self::Gmm(GaussianMixture::fit(data, k, &config.gmm, rng)?.0),
        })
    }

    pub fn kind(&self) -> CodebookKind {
        match self {
            Self::Kmeans(_) => CodebookKind::Kmeans,
            Self::Gmm(_) => CodebookKind::Gmm,
        }
    }

    fn inner(&self) -> &dyn Codebook {
        match self {
            Self::Kmeans(k) => k,
            Self::Gmm(g) => g,
        }
    }

    pub(crate) fn check(&self) -> Result<(), String> {
        match self {
            Self::Kmeans(k) => k.check(),
            // A GaussianMixture is validated when it is deserialised.
            Self::Gmm(_) => Ok(()),
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
