//! What every experiment of a run shares: the scale, the seed, where and how to run, the object
//! sets, the real recording, and the store of datasets and models.

use std::collections::{BTreeMap, HashMap};
use std::sync::{Arc, Mutex, PoisonError};

use super::PaperExperiment;
use super::data::{DataStore, Objects};
use super::real_frames_options::RealFramesOptions;
use super::scale::Scale;
use serde::Serialize;

use crate::dataset::recorded::{Calibration, RealData, RealImport, TaxelPitch, parse_real_csv};
use crate::dataset::{import_real, is_frames_csv};
use crate::experiment::runner::RunOptions;
use crate::experiment::unit::BoxError;
use crate::mesh::letters::LetterStyle;
use crate::mesh::letters::letter_from_name;
use crate::mesh::{NamedObject, ObjectSet, ObjectSource};
use crate::recognize::{CodebookKind, PosteriorRule};

/// The synthetic example recording shipped with the product (`data/real_letters_example.csv`):
/// the sim-to-real experiment's default input, so that its whole path runs without a recording.
pub const EXAMPLE_REAL_CSV: &str = include_str!("../../data/real_letters_example.csv");

/// A recording of real sensor frames: its frames and where they came from.
#[derive(Debug, Clone, PartialEq)]
pub struct RealRecording {
    pub origin: String,
    pub frames: RealFrames,
    /// Per-taxel gain and offset applied on import.
    pub calibration: Option<Calibration>,
    /// The recorded array's taxel pitch, when its maker gave it (`--taxel-pitch-m`): `sim-to-real`
    /// then simulates a pad of the recording's grid at this pitch instead of the paper's 6x6.
    pub taxel_pitch: Option<TaxelPitch>,
}

/// How a recording's frames are kept.
#[derive(Debug, Clone, PartialEq)]
pub enum RealFrames {
    /// A frames CSV's text (`dataset::recorded`).
    Csv(String),
    /// Frames kept otherwise (`dataset::import_real`: a folder of class folders of images, an
    /// `.npz`), read when needed.
    Kept(std::path::PathBuf),
}

impl RealRecording {
    /// The shipped synthetic example.
    pub fn example() -> Self {
        Self {
            origin: "data/real_letters_example.csv (built in)".into(),
            frames: RealFrames::Csv(EXAMPLE_REAL_CSV.into()),
            calibration: None,
            taxel_pitch: None,
        }
    }

    /// The recording at `path`: a frames CSV, a folder of class folders of images, or an `.npz`.
    pub fn read(path: &std::path::Path) -> Result<Self, BoxError> {
        let frames = if is_frames_csv(path) {
            RealFrames::Csv(std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?)
        } else {
            RealFrames::Kept(path.to_path_buf())
        };
        Ok(Self {
            origin: path.display().to_string(),
            frames,
            calibration: None,
            taxel_pitch: None,
        })
    }
}

/// Which objects a sweep recognises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Family {
    /// The 3D object set (`--objects`, default `shapes`).
    Shapes,
    /// The raised letters (`--letters`, default all 52).
    Letters,
    /// The letters named by the labels of the real recording (`--real`).
    RealLabels,
}

/// The shared state of a run of one or more paper experiments.
pub struct PaperContext {
    pub scale: Scale,
    pub seed: u64,
    pub options: RunOptions,
    /// The 3D objects (Figs. 7-14).
    pub shapes: ObjectSet,
    /// The raised letters (Fig. 16a) and the source of the sim-to-real letters.
    pub letters: ObjectSet,
    pub real: RealRecording,
    /// Fig. 16b's settings ([`RealFramesOptions`](super::RealFramesOptions)).
    pub real_frames: RealFramesOptions,
    /// `--codebook`: the codebook of every model when given; else each experiment's own
    /// ([`codebook_for`](Self::codebook_for)).
    pub codebook: Option<CodebookKind>,
    pub(crate) store: DataStore,
    built: Mutex<HashMap<String, Arc<Objects>>>,
}

impl PaperContext {
    pub fn new(
        scale: Scale,
        seed: u64,
        options: RunOptions,
        shapes: ObjectSet,
        letters: ObjectSet,
        real: RealRecording,
    ) -> Self {
        let threads = options.threads.map_or(0, std::num::NonZeroUsize::get);
        Self {
            store: DataStore::new(&options.out, threads),
            scale,
            seed,
            options,
            shapes,
            letters,
            real,
            real_frames: RealFramesOptions::default(),
            codebook: None,
            built: Mutex::new(HashMap::new()),
        }
    }

    /// The built objects of `family`, built once per run.
    pub fn objects(&self, family: Family) -> Result<Arc<Objects>, BoxError> {
        let set = match family {
            Family::Shapes => self.shapes.clone(),
            Family::Letters => self.letters.clone(),
            Family::RealLabels => self.real_letters()?,
        };
        let id = set.id();
        if let Some(built) = self.lock().get(&id) {
            return Ok(Arc::clone(built));
        }
        let built = Arc::new(Objects::build(set)?);
        self.lock().insert(id, Arc::clone(&built));
        Ok(built)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<String, Arc<Objects>>> {
        self.built.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The context with Fig. 16b's settings.
    pub fn with_real_frames(mut self, options: RealFramesOptions) -> Self {
        self.real_frames = options;
        self
    }

    /// Trains every model of every experiment with `codebook` (`None`: each experiment's own).
    pub fn with_codebook(mut self, codebook: Option<CodebookKind>) -> Self {
        self.codebook = codebook;
        self
    }

    /// The codebook of `experiment`'s models: `--codebook` when given, else the experiment's own
    /// ([`PaperExperiment::default_codebook`]).
    pub fn codebook_for(&self, experiment: PaperExperiment) -> CodebookKind {
        self.codebook.unwrap_or(experiment.default_codebook())
    }

    /// Recognises with the posterior `rule` (the calibrated one unless `--posterior eq15`).
    pub fn with_posterior(mut self, rule: PosteriorRule) -> Self {
        self.store.posterior = rule;
        self
    }

    /// The posterior rule every model recognises with.
    pub fn posterior(&self) -> PosteriorRule {
        self.store.posterior
    }

    /// The real recording, calibrated when it has a calibration, normalised to the sensing range by
    /// its largest value.
    pub fn real_data(&self) -> Result<Arc<RealData>, BoxError> {
        let options = RealImport {
            calibration: self.real.calibration.clone(),
            ..RealImport::default()
        };
        Ok(Arc::new(match &self.real.frames {
            RealFrames::Csv(text) => parse_real_csv(text, &self.real.origin, &options)?,
            RealFrames::Kept(path) => import_real(path, &options)?,
        }))
    }

    /// The letters the recording's labels name, each named by its label: a label is a single
    /// character (`A`) or a letter's object name (`upper_A`). Each is made as the letters set makes
    /// that letter (font and style); the built-in letters stand in when that set holds no generated
    /// letters.
    fn real_letters(&self) -> Result<ObjectSet, BoxError> {
        let real = self.real_data()?;
        let generated = |set: &ObjectSet| -> BTreeMap<char, ObjectSource> {
            set.objects
                .iter()
                .filter_map(|o| match &o.source {
                    ObjectSource::Letter { glyph, .. } => Some((*glyph, o.source.clone())),
                    _ => None,
                })
                .collect()
        };
        let mut sources = generated(&self.letters);
        if sources.is_empty() {
            sources = generated(&ObjectSet::default_letters(LetterStyle::default())?);
        }
        let mut objects = Vec::new();
        for label in real.labels() {
            let mut chars = label.chars();
            let glyph = match (chars.next(), chars.next()) {
                (Some(c), None) if c.is_ascii_alphabetic() => Some(c),
                _ => letter_from_name(label),
            }
            .ok_or_else(|| {
                format!(
                    "{}: {}: label '{label}' names no letter (labels are single letters such as 'A' or names such as 'upper_A')",
                    self.real.origin,
                    real.first_place_of(label).map_or_else(String::new, ToString::to_string)
                )
            })?;
            // A letter the set lacks is drawn like the set's other letters.
            let source = match sources.get(&glyph).or_else(|| sources.values().next()) {
                Some(ObjectSource::Letter { font, style, .. }) => ObjectSource::Letter {
                    glyph,
                    font: font.clone(),
                    style: *style,
                },
                _ => return Err("the letters set holds no letters".into()),
            };
            objects.push(NamedObject {
                name: label.to_string(),
                source,
            });
        }
        Ok(ObjectSet {
            name: "real-letters".into(),
            version: 1,
            diagonal_m: None,
            objects,
        })
    }
}
