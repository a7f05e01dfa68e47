//! The bag-of-features pipeline of Fig. 4 at test time: features -> PCA -> codebook membership
//! -> histogram -> decision.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::describe::Feature;
use crate::recognize::RecognizeError;
use crate::recognize::calibration::{PosteriorRule, Tempering};
use crate::recognize::codebook::{Codebook, CodebookModel};
use crate::recognize::features::FeatureMatrix;
use crate::recognize::features::check_feature;
use crate::recognize::object_model::{ClusterHistogram, ObjectModels};
use crate::recognize::pca::Pca;

/// A trained PCA, codebook and object models whose dimensions agree (checked on construction),
/// and the tempering its posterior applies (`recognize::calibration`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BagOfFeatures {
    pca: Pca,
    codebook: CodebookModel,
    models: ObjectModels,
    /// Fitted on validation trials by [`train`](crate::recognize::train); a model file written
    /// before calibration existed has none and recognises with Eq. 15 as it did.
    #[serde(default)]
    tempering: Tempering,
}

impl BagOfFeatures {
    /// Assembles the pipeline; the PCA output, the codebook input and the models' cluster count
    /// must agree.
    pub fn new(pca: Pca, codebook: CodebookModel, models: ObjectModels) -> Result<Self, RecognizeError> {
        let bag = Self {
            pca,
            codebook,
            models,
            tempering: Tempering::EQ15,
        };
        bag.check().map_err(|what| RecognizeError::InvalidParameter {
            name: "bag of features",
            what,
        })?;
        Ok(bag)
    }

    pub(crate) fn check(&self) -> Result<(), String> {
        self.pca.check()?;
        self.codebook.check()?;
        if self.codebook.dim() != self.pca.output_dim() {
            return Err(format!(
                "the codebook takes {} values, the PCA gives {}",
                self.codebook.dim(),
                self.pca.output_dim()
            ));
        }
        if self.codebook.kind().evidence_rule() != self.models.rule() {
            return Err(format!(
                "the {} codebook decides by {:?}, the object models by {:?}",
                self.codebook.kind().name(),
                self.codebook.kind().evidence_rule(),
                self.models.rule()
            ));
        }
        if self.codebook.clusters() != self.models.clusters() {
            return Err(format!(
                "the codebook has {} clusters, the object histograms {}",
                self.codebook.clusters(),
                self.models.clusters()
            ));
        }
        Ok(())
    }

    pub fn pca(&self) -> &Pca {
        &self.pca
    }

    pub fn codebook(&self) -> &CodebookModel {
        &self.codebook
    }

    pub fn models(&self) -> &ObjectModels {
        &self.models
    }

    pub fn objects(&self) -> &[String] {
        self.models.objects()
    }

    /// The tempering its posterior applies ([`Tempering::EQ15`] until one is fitted).
    pub fn tempering(&self) -> Tempering {
        self.tempering
    }

    /// The same pipeline with its posterior tempered by `tempering`.
    pub fn with_tempering(mut self, tempering: Tempering) -> Self {
        self.tempering = tempering;
        self
    }

    /// The same pipeline with the posterior `rule` applies: its fitted tempering or Eq. 15.
    pub fn with_posterior(self, rule: PosteriorRule) -> Self {
        let tempering = rule.tempering(self.tempering);
        self.with_tempering(tempering)
    }

    /// Length of the raw (descriptor) features it takes.
    pub fn input_dim(&self) -> usize {
        self.pca.input_dim()
    }

    /// Adds the memberships of raw `features` to `histogram`. Every feature is checked first
    /// (length, finiteness), so on error `histogram` is unchanged; `origin` names the features.
    pub fn add_features(
        &self,
        features: &[Feature],
        histogram: &mut ClusterHistogram,
        origin: &str,
    ) -> Result<(), RecognizeError> {
        for (i, f) in features.iter().enumerate() {
            check_feature(f, self.input_dim(), origin, i)?;
        }
        let mut reduced = vec![0.0; self.pca.output_dim()];
        let mut membership = vec![0.0; self.codebook.clusters()];
        for f in features {
            self.pca.transform_into(f, &mut reduced);
            self.codebook.membership(&reduced, &mut membership);
            histogram.add(&membership);
        }
        Ok(())
    }
}

/// The histogram of already PCA-reduced features under `codebook`, computed in fixed chunks on
/// several threads and summed in chunk order, so the result does not depend on the thread count.
pub fn reduced_histogram(codebook: &dyn Codebook, data: &FeatureMatrix) -> ClusterHistogram {
    const CHUNK: usize = 256;
    let k = codebook.clusters();
    let partials: Vec<ClusterHistogram> = data
        .as_slice()
        .par_chunks(CHUNK * data.dim())
        .map(|rows| {
            let mut h = ClusterHistogram::new(k);
            let mut membership = vec![0.0; k];
            for x in rows.chunks_exact(data.dim()) {
                codebook.membership(x, &mut membership);
                h.add(&membership);
            }
            h
        })
        .collect();
    let mut total = ClusterHistogram::new(k);
    for h in &partials {
        total.merge(h);
    }
    total
}
