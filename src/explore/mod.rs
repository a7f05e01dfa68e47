//! Exploration (Sec. III-A) and training-data collection (Sec. V-A3).

pub(crate) mod active;
pub(crate) mod cells;
pub(crate) mod collect;
pub(crate) mod grid;
pub(crate) mod planner;
pub(crate) mod reach;
pub(crate) mod report;
pub(crate) mod request;
pub(crate) mod sampler;
pub(crate) mod setup;
pub(crate) mod surface_sampling;
pub(crate) mod tree;

// Collecting a dataset: the sampler or the exploring arm, over a set of objects.
pub use collect::{
    BatchDataset, Collect, CollectError, CollectMode, CollectPlan, START_POSE_STREAM, SensorReader,
    collect_datasets, recorded_perturbation,
};
pub use grid::ReadingGrid;
pub use request::{CollectModeName, CollectRequest, ModeChoices, OtherModeChoices};
pub use setup::TouchSetup;

// The training sampler (Sec. V-A3) and the points it draws on the surface.
pub use sampler::{SamplerConfig, TrainingSampler};
pub use surface_sampling::{SurfacePoint, SurfaceSampler};

// The planner (Sec. III-A): its tree, how the arm reaches, and its report.
pub use planner::{
    AXIS_HEIGHT_FRACTION, ApproachRay, ITERATIONS_PER_READING, MAX_ATTEMPTS, PROPOSAL_DRAWS_PER_CANDIDATE,
    Planner, PlannerConfig, WORKSPACE_MARGIN_M, earns_a_retry, precise_kinematic_motion, precise_motion,
};
pub use reach::{ArmReach, carried};
pub use report::ExplorationReport;
pub use tree::{ExplorationTree, Vertex};

// Active touch: the next touch chosen by the posterior.
pub use active::{
    ActiveGuidance, ConfidenceStop, DEFAULT_CANDIDATES, ODDS_PRIOR_ITERATIONS, Probability, TouchOdds,
    TouchScorer, best_candidate, expected_gains,
};
