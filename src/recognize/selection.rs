//! Training with model selection (Sec. V-B1): over a grid of cluster counts `k` and several seeded
//! restarts, keep the model with the best validation accuracy, ties broken by reliability (the
//! probability the posterior puts on the correct object).

use std::borrow::Cow;
use std::sync::{Mutex, PoisonError};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::dataset::{ContactStatus, Dataset};
use crate::recognize::RecognizeError;
use crate::recognize::bag::{BagOfFeatures, reduced_histogram};
use crate::recognize::calibration::{EvidencePath, Tempering};
use crate::recognize::codebook::{Codebook, CodebookConfig, CodebookKind, CodebookModel};
use crate::recognize::features::FeatureMatrix;
use crate::recognize::features::TrainingFeatures;
use crate::recognize::labelled::LabelledFeatures;
use crate::recognize::neighbours::LeaveOneReadingOut;
use crate::recognize::object_model::{ClusterHistogram, ObjectModels, PseudoCount};
use crate::recognize::pca::{Pca, VarianceFraction};
use crate::recognize::trial::{Trial, make_trials};
use crate::rng::{stream, substream};
use crate::valid::{Check, Valid};

/// Everything that determines a trained model besides the data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainConfig {
    pub codebook: CodebookKind,
    /// The cluster counts to try, neighbour counts for [`CodebookKind::Knn`] ([`codebook_sizes`]
    /// chooses them for a problem).
    pub ks: Vec<usize>,
    /// Seeded restarts per `k` (one for a codebook that draws nothing at random,
    /// [`CodebookKind::is_random`]).
    pub restarts: usize,
    /// Restart `r` of `k` draws from `rng::stream(substream(seed, k), r)`, so adding values of
    /// `k` or restarts leaves the other candidates unchanged.
    pub seed: u64,
    pub variance_kept: VarianceFraction,
    pub pseudo_count: PseudoCount,
    pub fitting: CodebookConfig,
    /// Readings per validation trial: validation readings of each object are split into trials
    /// of this many consecutive readings, each classified as one unknown object.
    pub trial_readings: usize,
    /// Without a separate validation set, the last `holdout` of each object's training readings
    /// are held out for validation (1/11: the paper's 1000 + 100).
    pub holdout: f64,
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self {
            codebook: CodebookKind::Gmm,
            ks: vec![10, 20, 50],
            restarts: 3,
            seed: 0,
            variance_kept: VarianceFraction::PAPER,
            pseudo_count: PseudoCount::LAPLACE,
            fitting: CodebookConfig::default(),
            trial_readings: 10,
            holdout: 1.0 / 11.0,
        }
    }
}

impl Check for TrainConfig {
    type Error = RecognizeError;

    /// The grid and the trial length; the hold-out fraction, which [`LabelledFeatures::split_validation`]
    /// needs in `(0, 1)`. The PCA share and the pseudo-count are checked by their types, a codebook
    /// kind and a seed are any, and the codebook's fitting settings are checked by the fits.
    fn check(&self) -> Result<(), RecognizeError> {
        let Self {
            codebook: _,
            ks,
            restarts,
            seed: _,
            variance_kept: _,
            pseudo_count: _,
            fitting: _,
            trial_readings,
            holdout,
        } = self;
        let bad = |name, what: String| Err(RecognizeError::InvalidParameter { name, what });
        if ks.is_empty() {
            return bad("k", "give at least one cluster count".into());
        }
        if ks.contains(&0) {
            return bad("k", "cluster counts must be at least 1".into());
        }
        if *restarts == 0 {
            return bad("restarts", "must be at least 1".into());
        }
        if *trial_readings == 0 {
            return bad("trial_readings", "must be at least 1".into());
        }
        if !(*holdout > 0.0 && *holdout < 1.0) {
            return bad("holdout", format!("{holdout} is not a fraction in (0, 1)"));
        }
        Ok(())
    }
}

/// Training features a codebook needs per cluster: fewer leaves Gaussian components fitted to one
/// or two features each (kept positive definite only by `reg_covar`) and histograms that are
/// mostly pseudo-counts.
pub const MIN_FEATURES_PER_CLUSTER: usize = 5;

/// The cluster counts of `grid` that `training_features` features support (at least
/// [`MIN_FEATURES_PER_CLUSTER`] per cluster); when none does, the largest count that is supported
/// (at least 1). Small runs (the demo, experiments at small `--scale`) train on what they have.
pub fn supported_codebook_sizes(grid: &[usize], training_features: usize) -> Vec<usize> {
    sizes_up_to(grid, training_features / MIN_FEATURES_PER_CLUSTER)
}

/// The counts of `grid` up to `most`; when none is, `most` itself (at least 1).
fn sizes_up_to(grid: &[usize], most: usize) -> Vec<usize> {
    let most = most.max(1);
    let kept: Vec<usize> = grid.iter().copied().filter(|&k| k <= most).collect();
    if kept.is_empty() { vec![most] } else { kept }
}

/// The ladder the candidate cluster counts come from (roughly doubling).
const CODEBOOK_LADDER: [usize; 9] = [10, 20, 50, 100, 200, 400, 800, 1600, 3200];

/// The neighbour counts the neighbour codebook tries.
const NEIGHBOUR_COUNTS: [usize; 4] = [10, 20, 50, 100];

/// The hidden units the network tries ([`CodebookKind::Mlp`]): on the large-array benchmark 128
/// to 512 units were within a point of each other with the L2 penalty of `MlpConfig`.
const HIDDEN_UNITS: [usize; 2] = [128, 256];

/// Candidate cluster counts per problem: [`CODEBOOK_LADDER`] steps tried.
const CODEBOOK_STEPS: usize = 4;

/// The cluster counts model selection (Sec. V-B1) tries for `objects` objects and
/// `training_features` training features; validation accuracy, ties broken by reliability, then
/// picks one. The paper names no `k`; a fixed small grid starves large problems (on the 52 letters
/// validation accuracy kept rising from k = 10 to 400), so the grid starts at about one cluster per
/// object (the ladder value at or below `objects`, at least 10) and climbs `CODEBOOK_STEPS`
/// ladder steps: {10, 20, 50, 100} for 12 objects, {50, 100, 200, 400} for 52. Counts the
/// features cannot support are dropped ([`supported_codebook_sizes`]). `train`, `demo` and the
/// experiments all take their grid from here.
///
/// For the neighbour codebook ([`CodebookKind::Knn`]) the candidates are neighbour counts, {10, 20,
/// 50, 100}, kept below half an object's share of the training features (so an object's own
/// neighbourhood can outvote the rest); when none is, that half (at least 1). For the network
/// ([`CodebookKind::Mlp`]) they are hidden units, 128 and 256 whatever the problem: its
/// weights' penalty, not their number, keeps it from fitting the training features by heart.
pub fn codebook_sizes(kind: CodebookKind, objects: usize, training_features: usize) -> Vec<usize> {
    match kind {
        CodebookKind::Knn => return sizes_up_to(&NEIGHBOUR_COUNTS, training_features / objects.max(1) / 2),
        CodebookKind::Mlp => return HIDDEN_UNITS.to_vec(),
        CodebookKind::Gmm | CodebookKind::Kmeans => {}
    }
    let first = CODEBOOK_LADDER.iter().rposition(|&k| k <= objects).unwrap_or(0);
    let last = (first + CODEBOOK_STEPS).min(CODEBOOK_LADDER.len());
    supported_codebook_sizes(&CODEBOOK_LADDER[first..last], training_features)
}

impl TrainConfig {
    /// The training features that size the `k` grid ([`codebook_sizes`]) when `training_readings`
    /// converged readings train the model: one feature per reading, the fewest any descriptor gives
    /// (MR-8 gives one per image section, the others one), so that the grid holds for every
    /// descriptor of a fused model; less the share [`holdout`](Self::holdout) keeps for validation
    /// when there is no separate validation set, since those readings never reach the codebook.
    /// The one count the CLI's `train`, the demo and the experiments size their grids by (the CLI
    /// used to count the held-out readings too, and so could try a `k` the features left after the
    /// hold-out do not support).
    pub fn grid_training_features(&self, training_readings: usize, separate_validation: bool) -> usize {
        if separate_validation {
            training_readings
        } else {
            (training_readings as f64 * (1.0 - self.holdout)).floor() as usize
        }
    }

    /// This configuration with the `k` grid of [`codebook_sizes`] for its codebook, `objects`
    /// objects and the [`grid_training_features`](Self::grid_training_features) of
    /// `training_readings` converged training readings.
    pub fn with_grid_for(self, objects: usize, training_readings: usize, separate_validation: bool) -> Self {
        let features = self.grid_training_features(training_readings, separate_validation);
        Self {
            ks: codebook_sizes(self.codebook, objects, features),
            ..self
        }
    }

    /// [`with_grid_for`](Self::with_grid_for) the converged readings of `training`, over its
    /// header's objects (the objects a model trained on it knows).
    pub fn with_grid_for_dataset(self, training: &Dataset, separate_validation: bool) -> Self {
        let objects = training.header().objects.len();
        let converged = training
            .readings()
            .iter()
            .filter(|r| r.status == ContactStatus::Converged)
            .count();
        self.with_grid_for(objects, converged, separate_validation)
    }
}

/// One candidate's validation result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateScore {
    pub k: usize,
    pub restart: usize,
    /// Validation trials classified correctly, of `trials`.
    pub correct: usize,
    pub trials: usize,
    /// Mean probability on the correct object over the validation trials.
    pub reliability: f64,
    /// Why the candidate could not be fitted (e.g. a singular covariance); then it is not chosen.
    pub failure: Option<String>,
}

impl CandidateScore {
    pub fn accuracy(&self) -> f64 {
        if self.trials == 0 {
            0.0
        } else {
            self.correct as f64 / self.trials as f64
        }
    }

    /// Sec. V-B1's order: more correct, then higher reliability; a failed fit is never better.
    pub fn is_better_than(&self, other: &CandidateScore) -> bool {
        match (&self.failure, &other.failure) {
            (Some(_), _) => false,
            (None, Some(_)) => true,
            (None, None) => {
                self.correct > other.correct
                    || (self.correct == other.correct && self.reliability > other.reliability)
            }
        }
    }
}

/// What model selection tried and what it kept.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SelectionReport {
    pub chosen_k: usize,
    pub chosen_restart: usize,
    /// Every candidate, in the order tried (`k` in the given order, restarts within).
    pub candidates: Vec<CandidateScore>,
    /// Where the validation data came from.
    pub validation: String,
    /// Training readings and features used (after any hold-out).
    pub training_readings: usize,
    pub training_features: usize,
    /// Principal components kept, and the fraction of variance they explain.
    pub pca_components: usize,
    pub pca_variance_ratio: f64,
}

impl SelectionReport {
    /// The chosen candidate's score.
    pub fn chosen(&self) -> Option<&CandidateScore> {
        self.candidates
            .iter()
            .find(|c| c.k == self.chosen_k && c.restart == self.chosen_restart)
    }
}

/// What [`train`] reports while it runs (for progress bars).
#[derive(Debug, Clone, PartialEq)]
pub enum TrainProgress {
    /// PCA is fitted; `total` candidates follow.
    PcaFitted {
        components: usize,
        variance_ratio: f64,
        total: usize,
    },
    /// Candidate `index` of `total` is being fitted.
    Fitting {
        index: usize,
        total: usize,
        k: usize,
        restart: usize,
    },
    /// A candidate was scored.
    Scored(CandidateScore),
}

/// A trained pipeline and how it was chosen.
#[derive(Debug, Clone, PartialEq)]
pub struct Trained {
    pub bag: BagOfFeatures,
    pub selection: SelectionReport,
}

/// Trains on `training` (Fig. 4): PCA on all training features, then for every `k` and restart a
/// codebook and the objects' histograms, scored on validation trials; keeps the best candidate.
/// `validation` must name only training objects; without it, part of `training` is held out
/// ([`TrainConfig::holdout`]). The configuration comes checked (`Valid::new(TrainConfig { .. })?`),
/// linfa's params -> check -> fit.
///
/// # Example
///
/// Two objects whose readings give features near (0, 0) and near (5, 5) (a descriptor's output;
/// here written by hand): after training, three readings of the second make it the most probable
/// (the posterior of Eq. 15-16, updated after every reading).
///
/// ```
/// use taction::recognize::{LabelledFeatures, TrainConfig, train};
/// use taction::valid::Valid;
///
/// // Reading `i` of object `j`: one feature, near (5 j, 5 j).
/// let reading = |j: usize, i: usize| {
///     let (a, b) = (0.1 * (i % 7) as f64, 0.1 * (i % 5) as f64);
///     vec![vec![5.0 * j as f64 + a, 5.0 * j as f64 - b]]
/// };
/// let readings = (0..2).map(|j| (0..110).map(|i| reading(j, i)).collect()).collect();
/// let training = LabelledFeatures::new(vec!["cube".into(), "sphere".into()], readings)?;
/// let config = Valid::new(TrainConfig { ks: vec![2], restarts: 1, ..TrainConfig::default() })?;
/// let trained = train(&config, &training, None, &mut |_| {})?;
///
/// let mut posterior = trained.bag.posterior();
/// for i in 0..2 {
///     posterior.observe(&reading(1, i))?;
/// }
/// let belief = posterior.observe(&reading(1, 2))?;
/// assert_eq!(trained.bag.objects()[belief.guess()], "sphere");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn train(
    config: &Valid<TrainConfig>,
    training: &LabelledFeatures,
    validation: Option<&LabelledFeatures>,
    progress: &mut (dyn FnMut(TrainProgress) + Send),
) -> Result<Trained, RecognizeError> {
    let split = ValidationSplit::new(training, validation, config.holdout)?;
    let (training, validation) = (&*split.training, &*split.validation);
    check_every_object_read(training)?;
    let reduced = ReducedTraining::fit(training, config.variance_kept)?;
    let trials = make_trials(validation, training.objects(), config.trial_readings)?;
    let trials = reduce_trials(&reduced.pca, &trials)?;
    let fitted = fit_candidates(config, &reduced, training.objects(), &trials, progress);
    let chosen = choose_candidate(fitted)?;
    let evidence: Vec<EvidencePath> = trials
        .iter()
        .map(|t| evidence_path(&chosen.codebook, &chosen.models, t))
        .collect();
    let selection = SelectionReport {
        chosen_k: chosen.score.k,
        chosen_restart: chosen.score.restart,
        candidates: chosen.candidates,
        validation: split.origin,
        training_readings: training.reading_count(),
        training_features: reduced.reduced.rows(),
        pca_components: reduced.pca.output_dim(),
        pca_variance_ratio: reduced.pca.kept_variance_ratio(),
    };
    Ok(Trained {
        bag: BagOfFeatures::new(reduced.pca, chosen.codebook, chosen.models)?
            .with_tempering(Tempering::fit(&evidence)),
        selection,
    })
}

/// The readings a model is fitted on and those it is chosen on (Sec. V-B1), and where the latter
/// came from.
struct ValidationSplit<'a> {
    training: Cow<'a, LabelledFeatures>,
    validation: Cow<'a, LabelledFeatures>,
    origin: String,
}

impl<'a> ValidationSplit<'a> {
    /// `validation` when given, else the last `holdout` of each object's training readings.
    fn new(
        training: &'a LabelledFeatures,
        validation: Option<&'a LabelledFeatures>,
        holdout: f64,
    ) -> Result<Self, RecognizeError> {
        Ok(match validation {
            Some(v) => Self {
                training: Cow::Borrowed(training),
                validation: Cow::Borrowed(v),
                origin: "a separate validation set".to_string(),
            },
            None => {
                let (training, validation) = training.split_validation(holdout)?;
                Self {
                    training: Cow::Owned(training),
                    validation: Cow::Owned(validation),
                    origin: format!("the last {holdout:.3} of each object's training readings"),
                }
            }
        })
    }
}

/// Every object needs a training reading: an object without one has no histogram `p(c | O_j)`.
fn check_every_object_read(training: &LabelledFeatures) -> Result<(), RecognizeError> {
    let objects = training.objects();
    match (0..objects.len()).find(|&j| training.readings(j).iter().all(Vec::is_empty)) {
        Some(j) => Err(RecognizeError::EmptyObject {
            object: objects[j].clone(),
        }),
        None => Ok(()),
    }
}

/// The training features after PCA (Fig. 4's first step): all rows, each row's object and reading,
/// and the rows object by object (each object's block gives its histogram).
struct ReducedTraining {
    pca: Pca,
    reduced: FeatureMatrix,
    blocks: Vec<FeatureMatrix>,
    row_objects: Vec<u32>,
    row_readings: Vec<u32>,
    object_count: usize,
}

impl ReducedTraining {
    /// Fits the PCA keeping `variance_kept` on every training feature and reduces them.
    fn fit(training: &LabelledFeatures, variance_kept: VarianceFraction) -> Result<Self, RecognizeError> {
        let raw = FeatureMatrix::from_features(training.features(), "the training set")?;
        let pca = Pca::fit(&raw, variance_kept)?;
        let reduced = pca.transform(&raw);
        drop(raw);
        // Rows of `reduced` are object by object; each object's block gives its histogram.
        let object_count = training.objects().len();
        let mut blocks = Vec::with_capacity(object_count);
        let (mut row_objects, mut row_readings) = (Vec::new(), Vec::new());
        let mut reading_id = 0u32;
        let mut start = 0;
        for j in 0..object_count {
            for reading in training.readings(j) {
                row_objects.extend(std::iter::repeat_n(j as u32, reading.len()));
                row_readings.extend(std::iter::repeat_n(reading_id, reading.len()));
                reading_id += 1;
            }
            let n: usize = training.readings(j).iter().map(Vec::len).sum();
            blocks.push(FeatureMatrix::from_trusted(
                n,
                reduced.dim(),
                reduced.as_slice()[start * reduced.dim()..(start + n) * reduced.dim()].to_vec(),
            ));
            start += n;
        }
        Ok(Self {
            pca,
            reduced,
            blocks,
            row_objects,
            row_readings,
            object_count,
        })
    }

    fn features(&self) -> TrainingFeatures<'_> {
        TrainingFeatures {
            data: &self.reduced,
            objects: &self.row_objects,
            object_count: self.object_count,
            readings: &self.row_readings,
        }
    }
}

/// Every (k, restart) candidate of the grid, `k` in the given order, restarts within: one restart
/// for a codebook that draws nothing at random.
fn candidate_grid(config: &TrainConfig) -> Vec<(usize, usize)> {
    let restarts = if config.codebook.is_random() {
        config.restarts
    } else {
        1
    };
    config
        .ks
        .iter()
        .flat_map(|&k| (0..restarts).map(move |restart| (k, restart)))
        .collect()
}

/// Fits and scores every candidate of the grid. Each is fitted on its own random stream, in
/// parallel; the result is in grid order, so the model is the same for any thread count.
fn fit_candidates(
    config: &TrainConfig,
    reduced: &ReducedTraining,
    objects: &[String],
    trials: &[ReducedTrial],
    progress: &mut (dyn FnMut(TrainProgress) + Send),
) -> Vec<Candidate> {
    let jobs = candidate_grid(config);
    let total = jobs.len();
    progress(TrainProgress::PcaFitted {
        components: reduced.pca.output_dim(),
        variance_ratio: reduced.pca.kept_variance_ratio(),
        total,
    });
    let features = reduced.features();
    // The neighbour codebook's training histograms, for every candidate k, from one scan.
    let neighbours = (config.codebook == CodebookKind::Knn)
        .then(|| LeaveOneReadingOut::scan(features, config.ks.iter().copied().max().unwrap_or(1)));
    let candidate_training = CandidateTraining {
        features,
        pca: &reduced.pca,
        blocks: &reduced.blocks,
        neighbours: neighbours.as_ref(),
    };
    let progress = Mutex::new(progress);
    let report = |event: TrainProgress| {
        let mut progress = progress.lock().unwrap_or_else(PoisonError::into_inner);
        (*progress)(event);
    };
    jobs.par_iter()
        .enumerate()
        .map(|(index, &(k, restart))| {
            report(TrainProgress::Fitting {
                index,
                total,
                k,
                restart,
            });
            let candidate = fit_candidate(config, &candidate_training, objects, trials, k, restart);
            report(TrainProgress::Scored(candidate.score.clone()));
            candidate
        })
        .collect()
}

/// The candidate model selection keeps, and every candidate's score in grid order.
struct Chosen {
    score: CandidateScore,
    codebook: CodebookModel,
    models: ObjectModels,
    candidates: Vec<CandidateScore>,
}

/// Walks the candidates in grid order and keeps the best ([`CandidateScore::is_better_than`]: the
/// first of equals); when none was fitted, the first failure.
fn choose_candidate(fitted: Vec<Candidate>) -> Result<Chosen, RecognizeError> {
    let mut best: Option<(CandidateScore, CodebookModel, ObjectModels)> = None;
    let mut candidates = Vec::with_capacity(fitted.len());
    let mut first_error = None;
    for candidate in fitted {
        match candidate.fitted {
            Ok((cb, models)) => {
                if best
                    .as_ref()
                    .is_none_or(|(b, _, _)| candidate.score.is_better_than(b))
                {
                    best = Some((candidate.score.clone(), cb, models));
                }
            }
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
        candidates.push(candidate.score);
    }
    let Some((score, codebook, models)) = best else {
        return Err(
            first_error.unwrap_or_else(|| RecognizeError::NoFeatures("no candidate was fitted".into()))
        );
    };
    Ok(Chosen {
        score,
        codebook,
        models,
        candidates,
    })
}

/// One fitted and scored candidate of model selection; `fitted` is the error when the codebook or
/// the object models could not be fitted (then the candidate is never chosen).
struct Candidate {
    score: CandidateScore,
    fitted: Result<(CodebookModel, ObjectModels), RecognizeError>,
}

/// What every candidate is fitted on: the reduced training features, the same rows object by
/// object, and for the neighbour codebook every feature's nearest other-reading features.
struct CandidateTraining<'a> {
    features: TrainingFeatures<'a>,
    /// The PCA the features went through.
    pca: &'a Pca,
    blocks: &'a [FeatureMatrix],
    /// Present exactly when the codebook is [`CodebookKind::Knn`] (`train` scans for it).
    neighbours: Option<&'a LeaveOneReadingOut>,
}

/// Fits the codebook of `k` clusters on restart `restart`'s random stream, the objects' histograms
/// over it, and scores the pair on the validation trials.
fn fit_candidate(
    config: &TrainConfig,
    training: &CandidateTraining,
    objects: &[String],
    trials: &[ReducedTrial],
    k: usize,
    restart: usize,
) -> Candidate {
    let mut rng = stream(substream(config.seed, k as u64), restart as u64);
    let fitted = CodebookModel::fit(
        config.codebook,
        training.features,
        training.pca,
        k,
        &config.fitting,
        &mut rng,
    )
    .and_then(|cb| {
        debug_assert_eq!(matches!(cb, CodebookModel::Knn(_)), training.neighbours.is_some());
        let histograms: Vec<ClusterHistogram> = match training.neighbours {
            // A training feature must not count itself, nor its reading's other features.
            Some(neighbours) => neighbours.histograms(k),
            None => training
                .blocks
                .iter()
                .map(|b| reduced_histogram(&cb, b))
                .collect(),
        };
        let models = ObjectModels::fit(objects.to_vec(), &histograms, config.pseudo_count)?
            .with_rule(config.codebook.evidence_rule())?;
        Ok((cb, models))
    });
    let score = match &fitted {
        Ok((cb, models)) => score_candidate(cb, models, trials, k, restart),
        Err(e) => CandidateScore {
            k,
            restart,
            correct: 0,
            trials: trials.len(),
            reliability: 0.0,
            failure: Some(e.to_string()),
        },
    };
    Candidate { score, fitted }
}

/// A validation trial with its features already PCA-reduced, one matrix per reading.
struct ReducedTrial {
    object: usize,
    features: Vec<FeatureMatrix>,
}

fn reduce_trials(pca: &Pca, trials: &[Trial]) -> Result<Vec<ReducedTrial>, RecognizeError> {
    trials
        .iter()
        .map(|t| {
            let mut features = Vec::with_capacity(t.readings.len());
            for (r, reading) in t.readings.iter().enumerate() {
                if reading.is_empty() {
                    continue;
                }
                let origin = format!("validation reading {r} of an object");
                let m = FeatureMatrix::from_features(reading, &origin)?;
                if m.dim() != pca.input_dim() {
                    return Err(RecognizeError::FeatureDimension {
                        origin,
                        index: 0,
                        got: m.dim(),
                        expected: pca.input_dim(),
                    });
                }
                features.push(pca.transform(&m));
            }
            Ok(ReducedTrial {
                object: t.object,
                features,
            })
        })
        .collect()
}

/// Classifies every validation trial with all its readings.
fn score_candidate(
    codebook: &CodebookModel,
    models: &ObjectModels,
    trials: &[ReducedTrial],
    k: usize,
    restart: usize,
) -> CandidateScore {
    let mut correct = 0;
    let mut reliability = 0.0;
    let mut membership = vec![0.0; codebook.clusters()];
    for t in trials {
        let mut histogram = models.empty_histogram();
        for m in &t.features {
            add_reading(codebook, m, &mut histogram, &mut membership);
        }
        let decision = models.decide(&histogram);
        if decision.guess == t.object {
            correct += 1;
        }
        reliability += decision.probabilities[t.object];
    }
    let n = trials.len();
    CandidateScore {
        k,
        restart,
        correct,
        trials: n,
        reliability: if n == 0 { 0.0 } else { reliability / n as f64 },
        failure: None,
    }
}

/// Adds one reading's reduced features to `histogram` (`membership` is scratch space).
fn add_reading(
    codebook: &CodebookModel,
    reading: &FeatureMatrix,
    histogram: &mut ClusterHistogram,
    membership: &mut [f64],
) {
    for x in reading.iter_rows() {
        codebook.membership(x, membership);
        histogram.add(membership);
    }
}

/// A validation trial's Eq. 15 log-likelihoods after each of its readings: what the posterior's
/// tempering is fitted on (`recognize::calibration`).
fn evidence_path(codebook: &CodebookModel, models: &ObjectModels, trial: &ReducedTrial) -> EvidencePath {
    let mut histogram = models.empty_histogram();
    let mut membership = vec![0.0; codebook.clusters()];
    let log_likelihoods = trial
        .features
        .iter()
        .map(|m| {
            add_reading(codebook, m, &mut histogram, &mut membership);
            models.log_likelihoods(&histogram)
        })
        .collect();
    EvidencePath {
        object: trial.object,
        log_likelihoods,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codebook_sizes_grow_with_the_objects_and_fit_the_features() {
        // Paper scale: 1000 training readings per object.
        assert_eq!(
            codebook_sizes(CodebookKind::Gmm, 52, 52_000),
            vec![50, 100, 200, 400]
        );
        assert_eq!(
            codebook_sizes(CodebookKind::Gmm, 12, 12_000),
            vec![10, 20, 50, 100]
        );
        assert_eq!(codebook_sizes(CodebookKind::Gmm, 2, 2_000), vec![10, 20, 50, 100]);
        assert_eq!(codebook_sizes(CodebookKind::Gmm, 5000, 10_000_000), vec![3200]);
        // 52 letters at a small scale: 30 readings each support k <= 312.
        assert_eq!(codebook_sizes(CodebookKind::Gmm, 52, 52 * 30), vec![50, 100, 200]);
        // Too few features for any: the largest count they support.
        assert_eq!(codebook_sizes(CodebookKind::Gmm, 52, 100), vec![20]);
        assert_eq!(codebook_sizes(CodebookKind::Gmm, 3, 0), vec![1]);
        // Neighbour counts: below half an object's share of the features.
        assert_eq!(
            codebook_sizes(CodebookKind::Knn, 52, 52_000),
            vec![10, 20, 50, 100]
        );
        assert_eq!(codebook_sizes(CodebookKind::Knn, 12, 12 * 60), vec![10, 20]);
        assert_eq!(codebook_sizes(CodebookKind::Knn, 12, 12 * 10), vec![5]);
        assert_eq!(codebook_sizes(CodebookKind::Knn, 3, 0), vec![1]);
    }

    /// The grid counts the readings that reach the codebook: without a separate validation set
    /// the held-out 1/11 does not (105 readings of 2 objects support k = 20 only with all of them).
    #[test]
    fn the_grid_counts_the_training_readings_left_after_the_hold_out() {
        let config = TrainConfig::default();
        assert_eq!(config.grid_training_features(105, true), 105);
        assert_eq!(config.grid_training_features(105, false), 95);
        assert_eq!(config.clone().with_grid_for(2, 105, true).ks, vec![10, 20]);
        assert_eq!(config.with_grid_for(2, 105, false).ks, vec![10]);
    }

    fn score(correct: usize, reliability: f64, failure: bool) -> CandidateScore {
        CandidateScore {
            k: 1,
            restart: 0,
            correct,
            trials: 10,
            reliability,
            failure: failure.then(|| "x".into()),
        }
    }

    #[test]
    fn accuracy_first_then_reliability_and_failures_last() {
        assert!(score(8, 0.1, false).is_better_than(&score(7, 0.9, false)));
        assert!(score(8, 0.6, false).is_better_than(&score(8, 0.5, false)));
        assert!(!score(8, 0.5, false).is_better_than(&score(8, 0.5, false)));
        assert!(score(0, 0.0, false).is_better_than(&score(9, 0.9, true)));
        assert!(!score(9, 0.9, true).is_better_than(&score(0, 0.0, false)));
    }
}

#[cfg(test)]
mod codebook_size_tests {
    use super::supported_codebook_sizes;

    #[test]
    fn codebook_sizes_shrink_to_what_the_features_support() {
        assert_eq!(supported_codebook_sizes(&[10, 20], 1800), vec![10, 20]);
        assert_eq!(supported_codebook_sizes(&[10, 20], 100), vec![10, 20]);
        assert_eq!(supported_codebook_sizes(&[10, 20], 99), vec![10]);
        assert_eq!(supported_codebook_sizes(&[10, 20], 22), vec![4]);
        assert_eq!(supported_codebook_sizes(&[10, 20], 3), vec![1]);
        assert_eq!(supported_codebook_sizes(&[10, 20], 0), vec![1]);
    }
}
