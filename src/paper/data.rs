//! The readings and models the paper's experiments share, collected or trained once and kept on
//! disk under the output root, so that experiments of one `reproduce` (and reruns after a kill)
//! reuse them:
//!
//! ```text
//! <out>/data/<set>-<generator>-<key>.csv     a dataset (format of `crate::dataset`)
//! <out>/models/<descriptor>-<key>.json       a trained model (format of `crate::recognize::model`),
//!                                            or one calibrated again on the arm's explorations
//! ```
//!
//! `<key>` is a hash of everything the file's content depends on (the object set's id and the
//! collection plan; for a model also the training and validation keys, the descriptor and the
//! training configuration, and the keys of the explorations it was calibrated on), so a file is
//! reused exactly when it would be recomputed identically.
//! Files are written atomically; a corrupt one is an error naming it.
//!
//! Datasets are collected in a preparation step before an experiment's units run ([`DataStore::
//! prepare`]), all those an experiment lacks as one batch of object tasks on the pool
//! ([`collect_datasets`]); units then only read them. Collecting inside the units instead would
//! make units that share a dataset wait on each other inside the thread pool.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Instant;

use serde::Serialize;

use super::timing::PhaseClock;
use crate::dataset::{Dataset, Shortfall, describe_shortfalls};
use crate::describe::Descriptor;
use crate::experiment::progress::Progress;
use crate::experiment::unit::{BoxError, rows_to_csv};
use crate::explore::{BatchDataset, CollectPlan, collect_datasets};
use crate::mesh::ObjectSet;
use crate::mesh::checksum::sha256_hex;
use crate::recognize::{PosteriorRule, TrainConfig, TrainedModel};
use crate::sim::ObjectSpec;
use crate::valid::Valid;

/// An object set with its meshes built and placed, ready for collection.
pub struct Objects {
    pub set: ObjectSet,
    pub specs: Vec<ObjectSpec>,
}

impl Objects {
    /// Builds every object of `set` (fetching the CGAL meshes when missing).
    pub fn build(set: ObjectSet) -> Result<Self, BoxError> {
        let specs = ObjectSpec::all_of(&set)?;
        Ok(Self { set, specs })
    }

    pub fn names(&self) -> Vec<String> {
        self.specs.iter().map(|o| o.name.clone()).collect()
    }
}

/// One dataset an experiment needs: the objects of a set, collected as a plan says.
#[derive(Clone, Serialize)]
pub struct DataRequest {
    #[serde(skip)]
    pub objects: Arc<Objects>,
    pub object_set: String,
    pub plan: CollectPlan,
}

impl DataRequest {
    pub fn new(objects: &Arc<Objects>, plan: CollectPlan) -> Self {
        Self {
            object_set: objects.set.id(),
            objects: Arc::clone(objects),
            plan,
        }
    }

    /// The hash of what the dataset's content depends on.
    pub fn key(&self) -> String {
        hash_of(self)
    }

    fn file_name(&self) -> String {
        let generator: String = self
            .plan
            .mode
            .generator_name()
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '.' {
                    c
                } else {
                    '-'
                }
            })
            .collect();
        format!("{}-{generator}-{}.csv", self.objects.set.name, self.key())
    }
}

/// The first 16 hex digits of the SHA-256 of `value`'s JSON.
fn hash_of<T: Serialize>(value: &T) -> String {
    let json = serde_json::to_string(value).unwrap_or_default();
    sha256_hex(json.as_bytes())[..16].to_string()
}

/// The datasets and models of one output root.
pub struct DataStore {
    root: PathBuf,
    threads: usize,
    datasets: Mutex<HashMap<String, Arc<Dataset>>>,
    /// The objects of each prepared dataset (by key) that got fewer converged readings than asked.
    shortfalls: Mutex<HashMap<String, Vec<Shortfall>>>,
    /// How every model's posterior turns likelihoods into probabilities (`--posterior`).
    pub(crate) posterior: PosteriorRule,
    /// The time spent preparing datasets and fitting models (`timing.rs`).
    pub(crate) clock: PhaseClock,
}

/// The file in an experiment's folder naming the datasets it used that fell short of their
/// readings: `dataset,object,converged,wanted`, one line per short object. It outlives the run
/// (and the git-ignored datasets), so a resumed run and a reader of shipped results see it too.
pub const SHORTFALLS_FILE: &str = "shortfalls.csv";

/// One short object of one dataset, a line of [`SHORTFALLS_FILE`].
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Serialize, serde::Deserialize)]
pub struct ShortObject {
    /// The dataset's file name under `<out>/data/`.
    pub dataset: String,
    pub object: String,
    pub converged: usize,
    pub wanted: usize,
}

impl std::fmt::Display for ShortObject {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {} {} of {} converged readings",
            self.dataset, self.object, self.converged, self.wanted
        )
    }
}

/// The short objects recorded in `experiment_dir` (none if it has no [`SHORTFALLS_FILE`]).
pub fn read_shortfalls(experiment_dir: &Path) -> Result<Vec<ShortObject>, BoxError> {
    let path = experiment_dir.join(SHORTFALLS_FILE);
    if !path.exists() {
        return Ok(Vec::new());
    }
    let mut reader = csv::Reader::from_path(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let rows: Result<Vec<ShortObject>, _> = reader.deserialize().collect();
    Ok(rows.map_err(|e| format!("{}: {e} (delete it; a rerun writes it again)", path.display()))?)
}

/// Adds `short` to `experiment_dir`'s [`SHORTFALLS_FILE`]: the union with what an earlier run
/// recorded, sorted, so a resumed run keeps the record of datasets it no longer needed to read.
fn record_shortfalls(experiment_dir: &Path, short: Vec<ShortObject>) -> Result<(), BoxError> {
    let mut all: BTreeSet<ShortObject> = read_shortfalls(experiment_dir)?.into_iter().collect();
    all.extend(short);
    let path = experiment_dir.join(SHORTFALLS_FILE);
    let bytes = rows_to_csv(&all.into_iter().collect::<Vec<_>>(), &path)?;
    crate::experiment::files::create_dir_all(experiment_dir)?;
    crate::atomic::write_atomic(&path, &bytes)?;
    Ok(())
}

impl DataStore {
    /// A store under `out`; collections run on `threads` threads (0: all cores).
    pub fn new(out: &Path, threads: usize) -> Self {
        Self {
            root: out.to_path_buf(),
            threads,
            datasets: Mutex::new(HashMap::new()),
            shortfalls: Mutex::new(HashMap::new()),
            posterior: PosteriorRule::default(),
            clock: PhaseClock::default(),
        }
    }

    fn dataset_path(&self, request: &DataRequest) -> PathBuf {
        self.root.join("data").join(request.file_name())
    }

    /// Makes every requested dataset available: read from disk when an earlier run wrote it,
    /// otherwise collected now (all the missing ones as one batch, each written when whole), each
    /// distinct dataset once. The short ones among them are recorded in `experiment_dir`'s
    /// [`SHORTFALLS_FILE`].
    pub fn prepare(&self, requests: &[DataRequest], experiment_dir: &Path) -> Result<(), BoxError> {
        self.clock
            .datasets(|| self.prepare_timed(requests, experiment_dir))
    }

    fn prepare_timed(&self, requests: &[DataRequest], experiment_dir: &Path) -> Result<(), BoxError> {
        let mut distinct = BTreeMap::new();
        for r in requests {
            distinct.entry(r.key()).or_insert(r);
        }
        let mut missing = Vec::new();
        for (key, request) in distinct {
            if self.lock().contains_key(&key) {
                continue;
            }
            let path = self.dataset_path(request);
            if path.exists() {
                let dataset = Dataset::read(&path).map_err(|e| {
                    format!("{e} (a dataset cached by an earlier run; delete the file to collect it again)")
                })?;
                self.keep(key, request, &path, dataset);
            } else {
                missing.push((key, request, path));
            }
        }
        self.collect(&missing)?;
        let short: Vec<ShortObject> = {
            let known = self.shortfalls.lock().unwrap_or_else(PoisonError::into_inner);
            requests
                .iter()
                .flat_map(|request| {
                    let shortfalls = known.get(&request.key()).map(Vec::as_slice).unwrap_or_default();
                    shortfalls.iter().map(|s| ShortObject {
                        dataset: request.file_name(),
                        object: s.object.clone(),
                        converged: s.converged,
                        wanted: s.wanted,
                    })
                })
                .collect()
        };
        if !short.is_empty() {
            record_shortfalls(experiment_dir, short)?;
        }
        Ok(())
    }

    /// Makes `dataset` (of `request`, read from or written to `path`) available under `key`,
    /// recording its short objects.
    fn keep(&self, key: String, request: &DataRequest, path: &Path, dataset: Dataset) {
        let short = dataset.shortfalls(request.plan.readings_per_object);
        if !short.is_empty() {
            // Accuracy counts an object read fewer times as `recognize::AccuracyPoint` defines
            // it; the user must still know it happened, now and when the run ends.
            eprintln!("  warning: {} ({})", describe_shortfalls(&short), path.display());
            self.shortfalls
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .insert(key.clone(), short);
        }
        self.lock().insert(key, Arc::new(dataset));
    }

    /// Collects the `missing` datasets (key, request, file) as one batch over the store's threads
    /// ([`collect_datasets`]: the pool stays busy from one dataset to the next), writing each to its
    /// file as soon as it is whole.
    fn collect(&self, missing: &[(String, &DataRequest, PathBuf)]) -> Result<(), BoxError> {
        if missing.is_empty() {
            return Ok(());
        }
        let started = Instant::now();
        let total = missing.len();
        for (n, (_, request, _)) in missing.iter().enumerate() {
            eprintln!(
                "collecting dataset {}/{total}: {} readings of each of {} objects ({}), {}x{} taxels",
                n + 1,
                request.plan.readings_per_object,
                request.objects.specs.len(),
                request.plan.mode.generator_name(),
                request.plan.sensor.rows,
                request.plan.sensor.cols,
            );
        }
        let asked: usize = missing
            .iter()
            .map(|(_, r, _)| r.objects.specs.len().saturating_mul(r.plan.readings_per_object))
            .sum();
        let name = match total {
            1 => "  dataset 1/1".to_string(),
            _ => format!("  datasets 1-{total}/{total}"),
        };
        let progress = Progress::new(&name, asked, "converged readings");
        let batch: Vec<BatchDataset> = missing
            .iter()
            .map(|(_, request, _)| BatchDataset {
                plan: request.plan,
                object_set: &request.object_set,
                objects: &request.objects.specs,
            })
            .collect();
        let converged = AtomicUsize::new(0);
        crate::experiment::files::create_dir_all(&self.root.join("data"))?;
        let write = |n: usize, dataset: Dataset| -> Result<(), BoxError> {
            let (key, request, path) = &missing[n];
            dataset.write(path)?;
            let converged_here = dataset.converged().count();
            converged.fetch_add(converged_here, Ordering::Relaxed);
            eprintln!(
                "  dataset {}/{total}: {} readings ({converged_here} converged) in {:.1} s -> {}",
                n + 1,
                dataset.len(),
                started.elapsed().as_secs_f64(),
                path.display()
            );
            self.keep(key.clone(), request, path, dataset);
            Ok(())
        };
        collect_datasets(&batch, self.threads, &|| progress.inc(), &write)?;
        progress.finish(converged.into_inner());
        Ok(())
    }

    /// A dataset made available by [`prepare`](Self::prepare).
    pub fn dataset(&self, request: &DataRequest) -> Result<Arc<Dataset>, BoxError> {
        self.lock().get(&request.key()).cloned().ok_or_else(|| {
            format!(
                "internal: dataset {} was not prepared before the units ran",
                request.file_name()
            )
            .into()
        })
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<String, Arc<Dataset>>> {
        self.datasets.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The model trained with `descriptor` and `config` on `training`, chosen on `validation`
    /// (and its posterior calibrated there), with the run's posterior rule:
    /// read from `<out>/models/` when an earlier run trained it, otherwise trained and saved.
    /// No two units of one experiment need the same model (one unit per setting and descriptor)
    /// and experiments run one after another, so no two threads save the same model file; nothing
    /// shares a lock inside the thread pool.
    pub fn model(
        &self,
        training: &DataRequest,
        validation: &DataRequest,
        descriptor: &dyn Descriptor,
        config: &TrainConfig,
    ) -> Result<TrainedModel, BoxError> {
        let path = self.model_path(training, validation, descriptor, config, None);
        if let Some(model) = self.cached_model(&path)? {
            return Ok(model);
        }
        let training_data = self.dataset(training)?;
        let validation_data = self.dataset(validation)?;
        let config = Valid::new(config.clone())?;
        let model = self.clock.training(|| {
            TrainedModel::fit(
                &config,
                &training_data,
                Some(&validation_data),
                descriptor,
                &mut |_| {},
            )
        })?;
        self.save_model(&model, &path)?;
        Ok(model.with_posterior(self.posterior))
    }

    /// [`model`](Self::model) with its posterior's tempering and confidence map fitted again on
    /// the arm's `explorations` in trials of `trial_readings` (`TrainedModel::calibrate_on_all`,
    /// timed as training), cached as a model of its own: the experiments on the default sensor
    /// share their models and their calibration explorations (`paper::figures`), so each
    /// calibration is fitted once per output root.
    pub fn arm_calibrated_model(
        &self,
        training: &DataRequest,
        validation: &DataRequest,
        descriptor: &dyn Descriptor,
        config: &TrainConfig,
        explorations: &[DataRequest],
        trial_readings: usize,
    ) -> Result<TrainedModel, BoxError> {
        let calibration = ArmCalibrationKey {
            explorations: explorations.iter().map(DataRequest::key).collect(),
            trial_readings,
        };
        let path = self.model_path(training, validation, descriptor, config, Some(calibration));
        if let Some(model) = self.cached_model(&path)? {
            return Ok(model);
        }
        let model = self.model(training, validation, descriptor, config)?;
        let data = explorations
            .iter()
            .map(|request| self.dataset(request))
            .collect::<Result<Vec<_>, _>>()?;
        let data: Vec<&Dataset> = data.iter().map(AsRef::as_ref).collect();
        let calibrated = self
            .clock
            .training(|| model.calibrate_on_all(&data, trial_readings))?;
        self.save_model(&calibrated, &path)?;
        Ok(calibrated.with_posterior(self.posterior))
    }

    /// Where the model of these inputs is cached: `<out>/models/<descriptor>-<key>.json`.
    fn model_path(
        &self,
        training: &DataRequest,
        validation: &DataRequest,
        descriptor: &dyn Descriptor,
        config: &TrainConfig,
        arm_calibration: Option<ArmCalibrationKey>,
    ) -> PathBuf {
        #[derive(Serialize)]
        struct ModelKey<'a> {
            training: String,
            validation: String,
            descriptor: crate::describe::DescriptorParams,
            config: &'a TrainConfig,
            /// Models cached before their posterior was calibrated are not reused.
            calibrated: bool,
            /// Absent for a model as trained, so their keys are those of earlier runs.
            #[serde(skip_serializing_if = "Option::is_none")]
            arm_calibration: Option<ArmCalibrationKey>,
        }
        let key = hash_of(&ModelKey {
            training: training.key(),
            validation: validation.key(),
            descriptor: descriptor.params(),
            config,
            calibrated: true,
            arm_calibration,
        });
        self.root
            .join("models")
            .join(format!("{}-{key}.json", descriptor.kind().name()))
    }

    /// The model an earlier run saved at `path`, with the run's posterior rule.
    fn cached_model(&self, path: &Path) -> Result<Option<TrainedModel>, BoxError> {
        if !path.exists() {
            return Ok(None);
        }
        TrainedModel::load(path)
            .map(|m| Some(m.with_posterior(self.posterior)))
            .map_err(|e| {
                format!("{e} (a model cached by an earlier run; delete the file to train it again)").into()
            })
    }

    fn save_model(&self, model: &TrainedModel, path: &Path) -> Result<(), BoxError> {
        crate::experiment::files::create_dir_all(&self.root.join("models"))?;
        Ok(model.save(path)?)
    }
}

/// What a model's posterior was calibrated on besides its validation data: the arm's explorations
/// (their dataset keys) in trials of `trial_readings`.
#[derive(Serialize)]
struct ArmCalibrationKey {
    explorations: Vec<String>,
    trial_readings: usize,
}
