//! What every command shares: the `--seed` and `--threads` flags (defined once, flattened into each
//! command that has them), the error kind that makes the exit code 2, and the advisory lock on an
//! output folder.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, Write};
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};

use clap::Args;
use taction::bodies::{FreeBody, FreeBodyRequestError};
use taction::control::ControlConfig;
use taction::paper::{DEFAULT_CONTACT_THRESHOLD, RealFramesOptions};
use taction::recognize::{CodebookKind, PosteriorRule};
use taction::valid::{Check, Valid};

/// The seed a command uses when `--seed` is not given.
pub const DEFAULT_SEED: u64 = 1;

/// `--seed`, the one source of randomness of a run.
#[derive(Debug, Clone, Copy, Args)]
pub struct SeedArg {
    /// Seed of every random draw of the run (poses, sensor noise, codebook restarts): the same
    /// seed gives the same output bit for bit, whatever --threads.
    #[arg(long, default_value_t = DEFAULT_SEED, value_name = "N")]
    pub seed: u64,
}

/// `--free-object` and its material: the object on a free joint instead of a mocap body (beyond
/// the paper), for every command that puts it under the arm.
#[derive(Debug, Clone, Copy, Default, Args)]
pub struct FreeObjectArgs {
    /// The object on a free joint instead of a mocap body (beyond the paper): it settles on the
    /// table under gravity and the covering pushes it (docs/guide.md, "A free object")
    #[arg(long)]
    pub free_object: bool,
    /// With --free-object: the object's density, kg/m3, in [10, 20000] [default: 1000]
    #[arg(long, allow_hyphen_values = true, value_name = "KG_M3")]
    pub object_density: Option<f64>,
    /// With --free-object: its sliding friction on the table and the arm, in [0, 2] [default: 0.8]
    #[arg(long, allow_hyphen_values = true)]
    pub object_friction: Option<f64>,
}

impl FreeObjectArgs {
    /// The material asked for ([`FreeBody::requested`]), its fields named by their flags.
    pub fn body(&self) -> Result<Option<FreeBody>, UsageError> {
        FreeBody::requested(self.free_object, self.object_density, self.object_friction).map_err(|e| {
            let flag = |field: &str| field.replace('_', "-");
            match e {
                FreeBodyRequestError::WithoutFreeObject { field } => {
                    UsageError(format!("--{}: only with --free-object", flag(field)))
                }
                FreeBodyRequestError::OutOfRange { field, value, error } => {
                    flag_error(&flag(field), value, error)
                }
            }
        })
    }
}

/// `--object-size-m`: the one rescale flag of every command that builds objects from the user's
/// meshes (a mesh read as metres can be millimetres; `taction::mesh::check_plausible` then refuses
/// it and points here).
#[derive(Debug, Clone, Copy, Default, Args)]
pub struct ObjectSizeArg {
    /// Rescale user meshes to this bounding diagonal, metres (centred, resting on the table);
    /// built-in sets keep their own size.
    #[arg(
        long = "object-size-m",
        alias = "diagonal-m",
        value_name = "M",
        allow_hyphen_values = true,
        value_parser = parse_object_size_m
    )]
    pub m: Option<f64>,
}

fn parse_object_size_m(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(m) if m.is_finite() && m > 0.0 => Ok(m),
        _ => Err(format!("'{text}' is not a positive number of metres")),
    }
}

/// How recorded frames are pruned and preprocessed (Sec. V-F), alike for `experiment real-frames`
/// and `dataset import`, which gives the same frames the same images.
#[derive(Debug, Clone, Copy, Args)]
pub struct PreprocessArgs {
    /// Frames whose largest taxel is below this fraction of the sensing range did not touch:
    /// `real-frames` (Fig. 16b) drops them before its split (the counts per label go to
    /// config.json), `dataset import` writes them as `no_contact` readings.
    #[arg(long, default_value_t = DEFAULT_CONTACT_THRESHOLD, value_name = "FRACTION", allow_hyphen_values = true)]
    pub contact_threshold: f64,
    /// Square root of every taxel before describing (Sec. V-F; off because `real-frames` trains and
    /// tests on frames of the same sensor).
    #[arg(long)]
    pub square_root: bool,
    /// Gaussian blur width in taxels before describing (Sec. V-F); 0 is off.
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "TAXELS",
        allow_hyphen_values = true
    )]
    pub blur_sigma: f64,
}

impl PreprocessArgs {
    /// The options these flags give, with `trials` of the whole split-train-test process, checked.
    pub fn options(&self, trials: usize) -> Result<RealFramesOptions, UsageError> {
        let options = RealFramesOptions {
            contact_threshold: self.contact_threshold,
            square_root: self.square_root,
            blur_sigma_taxels: self.blur_sigma,
            trials,
        };
        options.check().map_err(|e| UsageError(e.to_string()))?;
        Ok(options)
    }
}

/// Worker threads per core at most: beyond this the threads only wait for the cores and each
/// still reserves its stack.
pub const THREADS_PER_CORE: usize = 4;

/// `--threads`: 0 means one per core, and a count beyond [`THREADS_PER_CORE`] per core is refused.
#[derive(Debug, Clone, Copy, Args)]
pub struct ThreadsArg {
    /// Worker threads: 0 uses one per core; at most 4 per core. The output never depends on it.
    #[arg(long, default_value_t = 0, value_name = "N", value_parser = parse_threads)]
    pub threads: usize,
}

fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, NonZeroUsize::get)
}

/// A count flag that must be 1 or more.
pub fn parse_at_least_one(text: &str) -> Result<NonZeroUsize, String> {
    text.trim()
        .parse::<usize>()
        .ok()
        .and_then(NonZeroUsize::new)
        .ok_or_else(|| format!("'{text}' is not a whole number 1 or more"))
}

fn parse_threads(text: &str) -> Result<usize, String> {
    let n: usize = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a whole number of threads (0 uses one per core)"))?;
    let cores = cores();
    let most = THREADS_PER_CORE * cores;
    if n > most {
        return Err(format!(
            "{n} threads is more than {THREADS_PER_CORE} per core ({most} on this machine's {cores} cores); \
             0 uses one per core"
        ));
    }
    Ok(n)
}

impl ThreadsArg {
    /// The number of worker threads to start.
    pub fn count(&self) -> NonZeroUsize {
        NonZeroUsize::new(self.threads)
            .unwrap_or_else(|| NonZeroUsize::new(cores()).unwrap_or(NonZeroUsize::MIN))
    }
}

/// `--posterior`, how recognition turns likelihoods into probabilities.
#[derive(Debug, Clone, Copy, Args)]
pub struct PosteriorArg {
    /// calibrated (the tempering fitted when the model was trained: on the arm's explorations with
    /// `train --calibration`, where a stop at p = 0.95 was right 95-98% of the time on the arm's
    /// touches; else on held-out sampler readings, which leaves it overconfident on the arm's) | eq15
    /// (the paper's Eq. 15-16: readings counted as independent evidence). Models trained before
    /// calibration existed recognise with eq15.
    #[arg(long = "posterior", value_name = "RULE", default_value = "calibrated", value_parser = parse_posterior)]
    pub rule: PosteriorRule,
}

fn parse_posterior(name: &str) -> Result<PosteriorRule, String> {
    PosteriorRule::parse(name).map_err(|e| e.to_string())
}

/// Parses a `--codebook` value, naming the kinds there are when it is none of them.
pub fn parse_codebook(name: &str) -> Result<CodebookKind, String> {
    CodebookKind::parse(name)
}

/// `--control`, the surface contact controllers' configuration, shared by the commands that settle
/// the pad (`touch`, `collect`).
#[derive(Debug, Clone, Args)]
pub struct ControlArg {
    /// Controller configuration as JSON: any subset of the controllers' fields, units in their
    /// names (e.g. `{"target_mean_pressure": 0.4}` or `{"orient_edge_guard": true}`); an unknown
    /// field is an error naming it. `expected_noise_fraction` is always taken from `--noise`.
    #[arg(long, value_name = "FILE.json")]
    pub control: Option<PathBuf>,
}

/// A `--control` file that cannot be read, parsed or accepted.
#[derive(Debug, thiserror::Error)]
#[error("--control: {path}: {what}")]
pub struct ControlFileError {
    /// The file, or `(defaults)` without one.
    pub path: String,
    pub what: String,
}

impl ControlArg {
    /// The file's fields over the defaults, the controllers told to expect the sensor's noise
    /// (`noise_fraction`, as the sensor's), not yet checked.
    pub fn config(&self, noise_fraction: f64) -> Result<ControlConfig, ControlFileError> {
        let mut config = match &self.control {
            None => ControlConfig::default(),
            Some(path) => {
                let text = std::fs::read_to_string(path).map_err(|e| self.error(e))?;
                let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| self.error(e))?;
                // serde would also take a JSON array, field by field in order: a file of numbers
                // whose meaning depends on the struct's field order.
                let Some(fields) = value.as_object() else {
                    return Err(self.error("want a JSON object of the controllers' fields by name"));
                };
                // An experiment's config.json holds the field; a copy of it agrees with the sensor.
                let expected = fields
                    .get("expected_noise_fraction")
                    .map(serde_json::Value::as_f64);
                if let Some(value) = expected.filter(|v| *v != Some(noise_fraction)) {
                    let shown = value.map_or_else(|| "not a number".to_string(), |v| v.to_string());
                    return Err(self.error(format!(
                        "expected_noise_fraction {shown} is not the sensor's --noise {noise_fraction}: the \
                         controllers always expect the sensor's noise; leave the field out"
                    )));
                }
                serde_json::from_value(value).map_err(|e| self.error(e))?
            }
        };
        config.expected_noise_fraction = noise_fraction;
        Ok(config)
    }

    /// [`config`](Self::config), checked.
    pub fn valid(&self, noise_fraction: f64) -> Result<Valid<ControlConfig>, ControlFileError> {
        Valid::new(self.config(noise_fraction)?).map_err(|e| self.error(e))
    }

    /// An error naming the file (or the defaults) and `what` is wrong.
    pub fn error(&self, what: impl std::fmt::Display) -> ControlFileError {
        ControlFileError {
            path: self
                .control
                .as_ref()
                .map_or_else(|| "(defaults)".into(), |p| p.display().to_string()),
            what: what.to_string(),
        }
    }
}

/// A flag or flag combination that cannot work; `main` exits with 2 for it, as clap does for the
/// flags it rejects itself, and 1 for failures of a run.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// A usage error naming `flag` and what is wrong with its `value`.
pub fn flag_error(flag: &str, value: impl std::fmt::Display, what: impl std::fmt::Display) -> UsageError {
    UsageError(format!("--{flag} {value}: {what}"))
}

/// Checks, before any work, that `--{flag} PATH` can become the file a command writes: not a
/// folder, and not inside a path that is a file (else the run would collect or train first and
/// then fail on the write with the system's "Not a directory").
pub fn check_output_file(path: &Path, flag: &str) -> Result<(), UsageError> {
    let shown = path.display();
    if path.as_os_str().to_string_lossy().ends_with('/') {
        return Err(UsageError(format!(
            "--{flag} {shown}: ends in '/', which names a folder; give the file to write"
        )));
    }
    if path.is_dir() {
        return Err(UsageError(format!(
            "--{flag} {shown}: is a folder; give the file to write"
        )));
    }
    let file_above = path.ancestors().skip(1).find(|a| a.is_file());
    match file_above {
        Some(file) => Err(UsageError(format!(
            "--{flag} {shown}: {} is a file, not a folder",
            file.display()
        ))),
        None => Ok(()),
    }
}

/// Checks, before any work, that `--{flag} PATH` can become the folder a command writes into.
pub fn check_output_folder(path: &Path, flag: &str) -> Result<(), UsageError> {
    // `FILE/` is the file `FILE`: `is_file` says no to it, and the write fails after the work.
    let path: PathBuf = path.components().collect();
    let path = path.as_path();
    match path.ancestors().find(|a| a.is_file()) {
        Some(file) if file == path => Err(UsageError(format!(
            "--{flag} {}: is a file; give the folder to write into",
            path.display()
        ))),
        Some(file) => Err(UsageError(format!(
            "--{flag} {}: {} is a file, not a folder",
            path.display(),
            file.display()
        ))),
        None => Ok(()),
    }
}

/// Name of the lock file a run keeps in its output folder.
pub const LOCK_FILE: &str = ".taction.lock";

/// An advisory lock on an output folder, held until dropped (or the process ends, however it
/// ends): a second run into the same folder refuses at once, naming the holder's pid, instead of
/// redoing the first one's work beside it.
#[derive(Debug)]
pub struct OutputLock {
    _file: File,
}

impl OutputLock {
    /// Creates `dir` if needed and locks it; `flag` names the flag that chose it, for the message.
    pub fn acquire(dir: &Path, flag: &str) -> Result<Self, Box<dyn std::error::Error>> {
        let io = |path: &Path, e: std::io::Error| format!("--{flag} {}: {e}", path.display());
        check_output_folder(dir, flag)?;
        std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
        let path: PathBuf = dir.join(LOCK_FILE);
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(|e| io(&path, e))?;
        match file.try_lock() {
            Ok(()) => {
                file.set_len(0).map_err(|e| io(&path, e))?;
                file.rewind().map_err(|e| io(&path, e))?;
                writeln!(file, "{}", std::process::id()).map_err(|e| io(&path, e))?;
                Ok(Self { _file: file })
            }
            Err(TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = match holder.trim() {
                    "" => "another taction run".to_string(),
                    pid => format!("another taction run (pid {pid})"),
                };
                Err(format!(
                    "--{flag} {}: {holder} is writing there; wait for it to end or choose another --{flag}",
                    dir.display()
                )
                .into())
            }
            Err(TryLockError::Error(e)) => Err(io(&path, e).into()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threads_zero_means_every_core_and_too_many_are_refused() {
        assert_eq!(ThreadsArg { threads: 0 }.count().get(), cores());
        assert_eq!(ThreadsArg { threads: 3 }.count().get(), 3);
        assert_eq!(parse_threads("0"), Ok(0));
        let e = parse_threads("100000").unwrap_err();
        assert!(e.contains("per core") && e.contains("0 uses one per core"), "{e}");
        assert!(parse_threads("-1").is_err());
    }

    #[test]
    fn a_second_lock_on_a_folder_names_the_holder() {
        let dir = tempfile::tempdir().unwrap();
        let first = OutputLock::acquire(dir.path(), "out").unwrap();
        let e = OutputLock::acquire(dir.path(), "out").unwrap_err().to_string();
        assert!(e.contains(&format!("pid {}", std::process::id())), "{e}");
        drop(first);
        OutputLock::acquire(dir.path(), "out").unwrap();
    }
}
