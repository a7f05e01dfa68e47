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
    /// Pool runs that differ only in `--seed`: each recognition experiment's curves over every seed
    /// with a 90% interval that resamples seeds, summed reliability tables, plots.
    Pool(cli::pool::PoolArgs),
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
    /// Show what a dataset file holds (objects, readings per object and status, sensor), or import
    /// recorded sensor frames as a dataset.
    Dataset(cli::dataset::DatasetArgs),
    /// Recognise a test dataset touch by touch with a saved model; write posterior, accuracy, confusion CSVs.
    Recognize(cli::recognize::RecognizeArgs),
    /// Run the surface contact controllers once from a pad pose on a mesh; print the outcome as JSON.
    Touch(cli::touch::TouchArgs),
    /// Train a bag-of-features model (PCA, k-means or GMM codebook, object histograms) on a dataset.
    Train(cli::train::TrainArgs),
}

fn main() -> ExitCode {
    quiet_on_closed_stdout();
    // SAFETY: no thread has been started and nothing has used MuJoCo yet.
    unsafe { taction::sim::keep_mujoco_log_off_disk() };
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Collect(args) => cli::collect::run(args),
        Command::Demo(args) => cli::demo::run(args),
        Command::Describe(args) => cli::describe::run(args),
        Command::Experiment(args) => cli::experiment::run_experiment(args),
        Command::Reproduce(args) => cli::experiment::run_reproduce(args),
        Command::Merge(args) => cli::merge::run(args),
        Command::Pool(args) => cli::pool::run(args),
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
        Err(e) if closed_stdout(e.as_ref()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("taction: {e}");
            if cli::is_usage_error(e.as_ref()) {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}

/// A reader that stops reading (`taction experiment list | head -1`) ends the program quietly and
/// successfully, as it ends any Unix filter: `println!` reports the closed pipe by panicking, so
/// that one panic exits 0 without a message; every other panic keeps the default report.
fn quiet_on_closed_stdout() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if message.starts_with("failed printing to stdout") && message.contains("Broken pipe") {
            std::process::exit(0);
        }
        default(info);
    }));
}

/// Whether `e` (or what caused it) is a write into a pipe whose reader has gone: the commands
/// that write their output through a buffer (`describe`) report it as an error rather than a
/// panic, and it ends them as quietly as a `println!`.
fn closed_stdout(e: &(dyn std::error::Error + 'static)) -> bool {
    let mut next = Some(e);
    while let Some(error) = next {
        if error
            .downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
        {
            return true;
        }
        next = error.source();
    }
    false
}
