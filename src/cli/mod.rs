//! One file per subcommand: its clap arguments and its `run` function. `main.rs` only dispatches.

pub mod demo;
