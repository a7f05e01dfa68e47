//! The `taction` command line: thin; parses and validates flags, then calls the library.

mod cli;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "taction",
    version,
    about = "Tactile object recognition from appearance information"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Collect readings of objects with the training sampler or the exploring arm; write a dataset.
    Collect(cli::collect::CollectArgs),
    /// Train on a small object set, explore an unknown object with the arm, recognise it touch by touch.
    Demo(cli::demo::DemoArgs),
    /// Print the feature vectors of one tactile image (Sec. IV-B), one per line, comma-separated.
    Describe(cli::describe::DescribeArgs),
    /// Run one experiment of the paper (Sec. V) as a resumable, shardable job; `experiment list` lists them.
    Experiment(cli::experiment::ExperimentArgs),
    /// Run every experiment of the paper, then print the headline accuracy table.
    Reproduce(cli::experiment::ReproduceArgs),
    /// Combine the output directories of sharded experiment runs (`--shard k/n`) into one.
    Merge(cli::merge::MergeArgs),
    /// Object sets: list them, fetch the 3D meshes, write the raised letters, export a set as OBJ.
    Objects(cli::objects::ObjectsArgs),
    /// Print the absolute path of the taction.covering MuJoCo plugin library (for mj_loadPluginLibrary).
    ///
    /// `cargo xtask setup` builds it (target/release/libtaction_covering.so). Python:
    /// `mujoco.mj_loadPluginLibrary(path)` before loading a model that uses the sensor, or copy the
    /// library into `mujoco.PLUGINS_DIR` (the plugin/ folder of the installed mujoco package), which
    /// every `import mujoco` loads, `python -m mujoco.viewer` included.
    PluginPath(cli::plugin_path::PluginPathArgs),
    /// The world as MJCF for MuJoCo's own tools: `scene export` writes arm, table, an object and the sensor.
    Scene(cli::scene::SceneArgs),
    /// One raw reading of the free-floating tactile sensor on a mesh, written as CSV or PNG.
    Sense(cli::sense::SenseArgs),
    /// Show what a dataset file holds: objects, readings per object and status, sensor configuration.
    Dataset(cli::dataset::DatasetArgs),
    /// Recognise a test dataset touch by touch with a saved model; write posterior, accuracy, confusion CSVs.
    Recognize(cli::recognize::RecognizeArgs),
    /// Run the surface contact controllers once from a pad pose on a mesh; print the outcome as JSON.
    Touch(cli::touch::TouchArgs),
    /// Train a bag-of-features model (PCA, k-means or GMM codebook, object histograms) on a dataset.
    Train(cli::train::TrainArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Collect(args) => cli::collect::run(args),
        Command::Demo(args) => cli::demo::run(args),
        Command::Describe(args) => cli::describe::run(args),
        Command::Experiment(args) => cli::experiment::run_experiment(args),
        Command::Reproduce(args) => cli::experiment::run_reproduce(args),
        Command::Merge(args) => cli::merge::run(args),
        Command::Objects(args) => cli::objects::run(args),
        Command::PluginPath(args) => cli::plugin_path::run(args),
        Command::Scene(args) => cli::scene::run(args),
        Command::Sense(args) => cli::sense::run(args),
        Command::Dataset(args) => cli::dataset::run(args),
        Command::Recognize(args) => cli::recognize::run(args),
        Command::Touch(args) => cli::touch::run(args),
        Command::Train(args) => cli::train::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("taction: {e}");
            ExitCode::FAILURE
        }
    }
}
