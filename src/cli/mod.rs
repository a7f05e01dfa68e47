//! One file per subcommand: its clap arguments and its `run` function. `main.rs` only dispatches.

pub mod collect;
pub mod common;
pub mod dataset;
pub mod demo;
pub mod describe;
pub mod experiment;
pub mod merge;
pub mod objects;
pub mod plausible;
pub mod plugin_path;
pub mod pool;
pub mod recognize;
pub mod scene;
pub mod sense;
pub mod sensor_args;
pub mod touch;
pub mod train;

/// Whether `e` is a bad flag (exit code 2) rather than a failure of the run (exit code 1).
pub fn is_usage_error(e: &(dyn std::error::Error + 'static)) -> bool {
    use sense::SenseError;
    use touch::TouchError;
    e.is::<common::UsageError>()
        || e.is::<sensor_args::SensorFlagError>()
        || e.is::<sensor_args::PadFrameError>()
        || matches!(
            e.downcast_ref::<SenseError>(),
            Some(SenseError::Flag(_) | SenseError::PadFrame(_) | SenseError::OutFormat(_))
        )
        || matches!(
            e.downcast_ref::<TouchError>(),
            Some(TouchError::Flag(_) | TouchError::PadFrame(_) | TouchError::TargetPressure(_))
        )
}
