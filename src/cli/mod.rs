//! One file per subcommand: its clap arguments and its `run` function. `main.rs` only dispatches.

pub mod collect;
pub mod dataset;
pub mod demo;
pub mod describe;
pub mod experiment;
pub mod merge;
pub mod objects;
pub mod plugin_path;
pub mod recognize;
pub mod scene;
pub mod sense;
pub mod sensor_args;
pub mod touch;
pub mod train;
