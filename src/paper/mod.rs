//! The experiments of the paper's Sec. V, each a resumable, shardable run on the experiment
//! framework writing tidy CSV and a plot like the paper's figure (`taction experiment NAME`), and
//! all of them in one command (`taction reproduce`).
//!
//! | name | figure | varies |
//! |---|---|---|
//! | `exploration` | 1 | - (one planner run on the chess piece, drawn; `figure1.rs`) |
//! | `descriptors` | 7 | the six descriptors |
//! | `strategy` | 8 | L, the probability of local exploration |
//! | `validation` | 9 | validation (sampler) vs exploration (planner) test data |
//! | `perturbation` | 10 | object fixed vs perturbed after every reading |
//! | `thickness` | 11 | covering thickness |
//! | `resolution` | 12 | taxels per side |
//! | `noise` | 13 | additive noise |
//! | `convergence` | 14 | controller convergence against noise ([`convergence_experiment`]) |
//! | `letters` | 16a | - (52 raised letters, sampler from above) |
//! | `real-frames` | 16b | - (trained and tested on recorded frames, 7 random splits; [`RealFramesOptions`]) |
//! | `sim-to-real` | 17 | - (trained in simulation, tested on recorded frames) |
//! | `training-size` | beyond | training readings per object (100, 300, 1000, 3000, 10,000) |
//! | `active` | beyond | active touch by expected information gain vs L = 1, 0.5; touches to confidence (`active.rs`) |
//! | `end-to-end` | beyond | the arm's blind touches recognised by the paper's training and ours (L, fixed/perturbed) |
//! | `fusion` | beyond | appearance, contact geometry and their fusion at random start poses (blind L and the fused model's active touch, fixed/perturbed), against readings and touch attempts (`fusion.rs`) |
//! | `free-object` | beyond | the object mocap, free (three densities, two frictions) or pushed: how far touches move it, Press's convergence, recognition (`free_object.rs`) |
//!
//! Datasets and models are shared between the experiments of a run through `<out>/data` and
//! `<out>/models` (`data.rs`, [`read_shortfalls`]).

pub(crate) mod active;
pub(crate) mod context;
pub(crate) mod convergence;
pub(crate) mod data;
pub(crate) mod estimate;
pub(crate) mod figure1;
pub(crate) mod figures;
pub(crate) mod free_object;
pub(crate) mod fusion;
pub(crate) mod headline;
pub(crate) mod real_frames;
pub(crate) mod real_frames_options;
pub(crate) mod recognition;
pub(crate) mod scale;
pub(crate) mod sim_to_real;
pub(crate) mod split;
pub(crate) mod timing;

use std::fmt;
use std::path::PathBuf;

// A run of the paper's experiments: its context (objects, recordings, scale) and the shared data
// under `<out>/data`; the time it will take; the headline table `reproduce` prints.
pub use context::{EXAMPLE_REAL_CSV, Family, PaperContext, RealFrames, RealRecording};
pub use data::{SHORTFALLS_FILE, read_shortfalls};
pub use estimate::{PACE_AFTER_S, REFERENCE_THREADS, RunEstimate, human_duration};
pub use headline::{HEADLINE_READINGS, headline_table};
pub use scale::{DataCounts, Scale, ScaleError};
pub use timing::{PhaseTimes, TIMINGS_FILE, timings_table, write_timings};

// The recognition figures: a sweep of settings, each a curve over the readings.
pub use recognition::{Curve, RecognitionSweep, Setting, TestData};
pub use split::{Split, SplitError, SplitSizes, split_per_label};

// Fig. 1: the exploration drawn.
pub use figure1::{
    ExplorationView, PAPER_IMAGES_SHOWN, Placement, RgbPicture, render_exploration, write_exploration_png,
};

// Fig. 14: controller convergence against noise.
pub use convergence::{
    ConvergencePlan, ConvergenceRow, MIN_CONVERGENCES, PAPER_NOISE_FRACTIONS, convergence_experiment,
    convergences_at, paper_object,
};

// Fig. 16b and 17: recorded frames of a real sensor, pruned and split; the simulation made to look
// like them.
pub use real_frames::{prune, recorded_dataset, scaled_split_sizes, trial_split};
pub use real_frames_options::{DEFAULT_CONTACT_THRESHOLD, PAPER_TRIALS, RealFramesOptions};
pub use sim_to_real::{GaussianBlur, SimToRealPreprocess, square_root};

use crate::experiment::runner::{RunReport, run};
use crate::experiment::unit::BoxError;
use crate::recognize::CodebookKind;

/// One experiment of the paper.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PaperExperiment {
    Exploration,
    Descriptors,
    Strategy,
    Validation,
    Perturbation,
    Thickness,
    Resolution,
    Noise,
    Convergence,
    Letters,
    RealFrames,
    SimToReal,
    TrainingSize,
    Active,
    EndToEnd,
    Fusion,
    FreeObject,
}

impl PaperExperiment {
    /// Every experiment, in the order `reproduce` runs them (the paper's figure order, then the
    /// experiments beyond the paper).
    pub const ALL: [PaperExperiment; 17] = [
        Self::Exploration,
        Self::Descriptors,
        Self::Strategy,
        Self::Validation,
        Self::Perturbation,
        Self::Thickness,
        Self::Resolution,
        Self::Noise,
        Self::Convergence,
        Self::Letters,
        Self::RealFrames,
        Self::SimToReal,
        Self::TrainingSize,
        Self::Active,
        Self::EndToEnd,
        Self::Fusion,
        Self::FreeObject,
    ];

    /// The recognition figure's sweep; `None` for Fig. 1, a picture, Fig. 14, which is not a
    /// recognition curve, and Fig. 16b, which trains on recorded frames rather than on simulated
    /// readings.
    fn sweep(self) -> Option<RecognitionSweep> {
        Some(match self {
            Self::Descriptors => figures::descriptors(),
            Self::Strategy => figures::strategy(),
            Self::Validation => figures::validation(),
            Self::Perturbation => figures::perturbation(),
            Self::Thickness => figures::thickness(),
            Self::Resolution => figures::resolution(),
            Self::Noise => figures::noise(),
            Self::Exploration
            | Self::Convergence
            | Self::RealFrames
            | Self::Active
            | Self::Fusion
            | Self::FreeObject => {
                return None;
            }
            Self::Letters => figures::letters(),
            Self::SimToReal => figures::sim_to_real(),
            Self::TrainingSize => figures::training_size(),
            Self::EndToEnd => figures::end_to_end(),
        })
    }

    /// The codebook of the experiment's models when `--codebook` does not say: the paper's GMM
    /// (Sec. IV-C) for the paper's figures and the training-size study of its recipe; for the two
    /// experiments on the arm's own touches, `end-to-end` and `active`, the codebook of the recipe
    /// the product recognises them with (the demo's, [`ArmTrainingRecipe::CODEBOOK`]: the
    /// neighbour codebook), so that what they measure is what a user of the product gets.
    ///
    /// [`ArmTrainingRecipe::CODEBOOK`]: crate::active_touch::ArmTrainingRecipe::CODEBOOK
    pub fn default_codebook(self) -> CodebookKind {
        match self {
            Self::Active | Self::EndToEnd | Self::Fusion | Self::FreeObject => {
                crate::active_touch::ArmTrainingRecipe::CODEBOOK
            }
            _ => CodebookKind::Gmm,
        }
    }

    /// Whether the experiment's rows are recognition curves ([`crate::experiment::AccuracyRow`]'s
    /// columns; `active` adds the confidence stop's); Fig. 14's are convergence statistics and
    /// Fig. 1's the placements it draws.
    pub fn is_recognition(self) -> bool {
        !matches!(self, Self::Exploration | Self::Convergence)
    }

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Exploration => figure1::EXPERIMENT_NAME,
            Self::RealFrames => real_frames::EXPERIMENT_NAME,
            Self::Active => active::EXPERIMENT_NAME,
            Self::Fusion => fusion::EXPERIMENT_NAME,
            Self::FreeObject => free_object::EXPERIMENT_NAME,
            _ => self.sweep().map_or(convergence::EXPERIMENT_NAME, |s| s.name),
        }
    }

    pub fn description(self) -> &'static str {
        match self {
            Self::Exploration => return figure1::DESCRIPTION,
            Self::RealFrames => return real_frames::DESCRIPTION,
            Self::Active => return active::DESCRIPTION,
            Self::Fusion => return fusion::DESCRIPTION,
            Self::FreeObject => return free_object::DESCRIPTION,
            _ => {}
        }
        self.sweep().map_or(
            "Fig. 14: controller convergence and iterations against noise 0-150% (the dragon, or every 3D object without one)",
            |s| s.description,
        )
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|e| e.name() == name)
    }

    /// Runs the experiment in `context`.
    pub fn run(self, context: &PaperContext) -> Result<PaperOutput, BoxError> {
        let codebook = context.codebook_for(self);
        Ok(match self.sweep() {
            Some(sweep) => PaperOutput::Run(Box::new(sweep.run(context, codebook)?)),
            None if self == Self::Exploration => PaperOutput::Picture(figure1::run_figure1(context)?),
            None if self == Self::RealFrames => {
                PaperOutput::Run(Box::new(real_frames::run_real_frames(context, codebook)?))
            }
            None if self == Self::Active => {
                PaperOutput::Run(Box::new(active::run_active(context, codebook)?))
            }
            None if self == Self::Fusion => {
                PaperOutput::Run(Box::new(fusion::run_fusion(context, codebook)?))
            }
            None if self == Self::FreeObject => {
                PaperOutput::Run(Box::new(free_object::run_free_object(context, codebook)?))
            }
            None => PaperOutput::Run(Box::new(run_convergence(context)?)),
        })
    }

    /// [`run`](Self::run), and where its time went (`timing.rs`).
    pub fn run_timed(self, context: &PaperContext) -> Result<(PaperOutput, PhaseTimes), BoxError> {
        let before = context.store.clock.snapshot();
        let started = std::time::Instant::now();
        let output = self.run(context)?;
        let wall = started.elapsed();
        let times = PhaseTimes::of(self.name(), wall, before, context.store.clock.snapshot(), &output);
        Ok((output, times))
    }
}

/// What running a paper experiment produced: a run of units, or (Fig. 1) one picture.
#[derive(Debug)]
pub enum PaperOutput {
    Run(Box<RunReport>),
    Picture(PathBuf),
}

impl fmt::Display for PaperOutput {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Run(report) => report.fmt(f),
            Self::Picture(path) => write!(f, "wrote {}", path.display()),
        }
    }
}

/// Fig. 14 on the paper's object, the dragon, when the 3D set has one; otherwise on every object of
/// the set.
fn run_convergence(context: &PaperContext) -> Result<RunReport, BoxError> {
    let objects = context.objects(Family::Shapes)?;
    let dragon: Vec<_> = objects
        .specs
        .iter()
        .filter(|o| o.name == convergence::PAPER_OBJECT)
        .cloned()
        .collect();
    let chosen = if dragon.is_empty() {
        objects.specs.clone()
    } else {
        dragon
    };
    let experiment = convergence::convergence_experiment(chosen, context.scale.fraction(), context.seed)?;
    Ok(run(&experiment, &context.options)?)
}

impl fmt::Display for PaperExperiment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
