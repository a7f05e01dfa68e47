//! Fig. 1: "a chess piece being explored by our simulated robotic arm ... Yellow patches show the
//! sensor placements at which local controllers converged ... The corresponding tactile images are
//! shown to the right" (Sec. I), from "100 tactile images ... extracted using the planner, alongside
//! depictions of the first 50" (Sec. III-A). One planner run on the set's chess piece (the pawn, else
//! the first object), drawn by [`write_exploration_png`], with the placements as CSV.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::atomic::write_atomic;
use crate::experiment::index::{PICTURE_FILE, PictureSpec, write_index};
use crate::experiment::spec::to_json;
use crate::experiment::unit::{BoxError, rows_to_csv};
use crate::explore::PlannerConfig;
use crate::explore::collect::{CollectMode, CollectPlan};
use crate::paper::context::{Family, PaperContext};
use crate::paper::figures::default_sensor;
use crate::rng;
use crate::sim::{ObjectSpec, PerturbationBounds, StartPose};
use crate::valid::Valid;

mod render;

pub use render::{
    ExplorationView, PAPER_IMAGES_SHOWN, Placement, RgbPicture, render_exploration, write_exploration_png,
};

pub const EXPERIMENT_NAME: &str = "exploration";
pub const DESCRIPTION: &str = "Fig. 1: one planner exploration of the chess piece (L = 0.5, 100 converged readings), a patch at every converged placement, the first 50 tactile images beside it";
/// The object of the paper's figure, when the set has it.
pub const PAPER_OBJECT: &str = "pawn";
/// Converged readings of the figure (Sec. III-A).
pub const READINGS: usize = 100;
const STREAM: u64 = 0xF161;

/// One converged placement, in the object's frame (metres).
#[derive(Debug, Serialize)]
struct PlacementRow {
    object: String,
    reading: usize,
    center_x_m: f64,
    center_y_m: f64,
    center_z_m: f64,
    normal_x: f64,
    normal_y: f64,
    normal_z: f64,
    max_taxel: f64,
    seed: u64,
}

/// What the figure was made from (`config.json`).
#[derive(Debug, Serialize)]
struct Figure1Config<'a> {
    object: &'a str,
    plan: &'a CollectPlan,
}

/// Runs the exploration and writes `<out>/exploration/{exploration.png, exploration.csv,
/// config.json, picture.json}` (the index lists it from the last) and rewrites the results index,
/// as the runner does after every experiment; returns the picture's path.
pub fn run_figure1(context: &PaperContext) -> Result<PathBuf, BoxError> {
    let objects = context.objects(Family::Shapes)?;
    let object = objects
        .specs
        .iter()
        .find(|o| o.name == PAPER_OBJECT)
        .or_else(|| objects.specs.first())
        .ok_or("the 3D set has no object to explore")?;
    let plan = figure_plan(object, context.seed)?;
    let report = plan.collect_object(object, 0)?;
    let placements = Placement::from_readings(&report.readings);
    if placements.is_empty() {
        return Err(format!(
            "Fig. 1: the planner found no converged reading of '{}' in {} attempts",
            object.name,
            report.readings.len()
        )
        .into());
    }
    let dir = context.options.out.join(EXPERIMENT_NAME);
    let picture = dir.join(format!("{EXPERIMENT_NAME}.png"));
    write_exploration_png(&picture, &object.mesh, &object.pose, &placements, &plan.sensor)?;
    write_figure_files(&dir, object, &plan, &placements, context.seed)?;
    write_index(&context.options.out)?;
    if placements.len() < READINGS {
        eprintln!(
            "warning: Fig. 1: {} of {READINGS} converged readings of '{}' (the planner ran out of iterations)",
            placements.len(),
            object.name
        );
    }
    Ok(picture)
}

/// One planner run of [`READINGS`] converged readings, L = 0.5 (Sec. III-A), the object fixed.
fn figure_plan(object: &ObjectSpec, seed: u64) -> Result<CollectPlan, BoxError> {
    Ok(CollectPlan {
        mode: CollectMode::Planner(Valid::new(
            PlannerConfig {
                local_probability: 0.5,
                ..PlannerConfig::default()
            }
            .fitted_to(std::slice::from_ref(object)),
        )?),
        sensor: default_sensor(),
        control: Valid::default(),
        perturbation: PerturbationBounds::NONE,
        readings_per_object: READINGS,
        seed: rng::substream(seed, STREAM),
        start_pose: StartPose::Canonical,
        free_object: None,
    })
}

/// Beside the picture: the placements as CSV, `config.json` and `picture.json` (which the index
/// lists the picture by).
fn write_figure_files(
    dir: &Path,
    object: &ObjectSpec,
    plan: &CollectPlan,
    placements: &[Placement],
    seed: u64,
) -> Result<(), BoxError> {
    let csv = dir.join(format!("{EXPERIMENT_NAME}.csv"));
    write_atomic(
        &csv,
        &rows_to_csv(&placement_rows(object, placements, seed), &csv)?,
    )?;
    let config = dir.join("config.json");
    let config_bytes = to_json(
        &Figure1Config {
            object: &object.name,
            plan,
        },
        &config,
    )?;
    write_atomic(&config, &config_bytes)?;
    let spec_path = dir.join(PICTURE_FILE);
    let spec = PictureSpec {
        description: DESCRIPTION.to_string(),
        title: format!(
            "Fig. 1: {} converged placements on '{}' and the first tactile images",
            placements.len(),
            object.name
        ),
    };
    write_atomic(&spec_path, &to_json(&spec, &spec_path)?)?;
    Ok(())
}

/// One row per converged placement, numbered from 1.
fn placement_rows(object: &ObjectSpec, placements: &[Placement], seed: u64) -> Vec<PlacementRow> {
    placements
        .iter()
        .enumerate()
        .map(|(k, p)| PlacementRow {
            object: object.name.clone(),
            reading: k + 1,
            center_x_m: p.pad_in_object.center_m.x,
            center_y_m: p.pad_in_object.center_m.y,
            center_z_m: p.pad_in_object.center_m.z,
            normal_x: p.pad_in_object.normal.x,
            normal_y: p.pad_in_object.normal.y,
            normal_z: p.pad_in_object.normal.z,
            max_taxel: p.image.values().iter().copied().fold(0.0, f64::max),
            seed,
        })
        .collect()
}
