//! What every command shares: the `--seed` and `--threads` flags (defined once, flattened into each
//! command that has them), the error kind that makes the exit code 2, and the advisory lock on an
//! output folder.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, Write};
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};

use clap::Args;

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

/// A flag or flag combination that cannot work; `main` exits with 2 for it, as clap does for the
/// flags it rejects itself, and 1 for failures of a run.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// A usage error naming `flag` and what is wrong with its `value`.
pub fn flag_error(flag: &str, value: impl std::fmt::Display, what: impl std::fmt::Display) -> UsageError {
    UsageError(format!("--{flag} {value}: {what}"))
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
