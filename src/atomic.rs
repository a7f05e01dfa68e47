//! Atomic file replacement, for every file the program writes: what makes a killed run safe to
//! resume and a reader never see half a file.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// A file that could not be written (or a folder that could not be read or created), named.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
pub struct FileError {
    pub path: PathBuf,
    pub source: std::io::Error,
}

impl FileError {
    fn at(path: &Path) -> impl FnOnce(std::io::Error) -> Self + '_ {
        move |source| Self {
            path: path.to_path_buf(),
            source,
        }
    }
}

static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to `path` so that, whenever the process dies, `path` holds either its previous
/// content (or nothing) or all of `bytes`, never a part: the bytes go to a hidden temporary file in
/// the same directory, are flushed to disk, and the temporary is renamed over `path` (rename is
/// atomic within a POSIX file system). The directory is created if missing.
///
/// Temporary names are `.<file name>.<pid>.<counter>.tmp`, unique across threads and processes, so
/// shards writing into one directory never collide. A temporary left by a killed run is hidden,
/// ignored by every reader, and deleted by the next run or merge there
/// ([`remove_stale_temporaries`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(FileError::at(dir))?;
    let temp = temp_path(path);
    let result = write_then_rename(&temp, path, bytes);
    if result.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    result
}

/// [`write_atomic`] unless `path` already holds exactly `bytes`: re-assembling a finished
/// experiment then costs reads, not flushes to disk, and leaves modification times alone.
pub fn write_if_changed(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    match std::fs::read(path) {
        Ok(existing) if existing == bytes => Ok(()),
        _ => write_atomic(path, bytes),
    }
}

fn write_then_rename(temp: &Path, path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    let mut file = std::fs::File::create(temp).map_err(FileError::at(temp))?;
    file.write_all(bytes).map_err(FileError::at(temp))?;
    file.sync_all().map_err(FileError::at(temp))?;
    drop(file);
    std::fs::rename(temp, path).map_err(FileError::at(path))
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.{}.{n}.tmp", std::process::id()))
}

/// Deletes `path` if it is there: an output an earlier run into the same folder wrote and this
/// run does not, which would otherwise stand beside fresh files as if this run had written it.
pub fn remove_if_present(path: &Path) -> Result<(), FileError> {
    match std::fs::remove_file(path) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(source) => Err(FileError::at(path)(source)),
    }
}

/// Deletes the temporaries of [`write_atomic`] in `dir` left by processes that no longer run (a
/// killed run), judged by the process id in their name; returns how many. Temporaries of live
/// processes, such as another shard writing into the same directory, are left alone. Where `/proc`
/// does not exist nothing is deleted (the temporaries stay hidden and ignored).
pub fn remove_stale_temporaries(dir: &Path) -> Result<usize, FileError> {
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return Ok(0);
    }
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(0),
        Err(source) => return Err(FileError::at(dir)(source)),
    };
    let mut removed = 0;
    for entry in entries {
        let entry = entry.map_err(FileError::at(dir))?;
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(temporary_pid) else {
            continue;
        };
        if pid != std::process::id() && !proc.join(pid.to_string()).exists() {
            match std::fs::remove_file(entry.path()) {
                Ok(()) => removed += 1,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(source) => return Err(FileError::at(&entry.path())(source)),
            }
        }
    }
    Ok(removed)
}

/// The process id in a temporary's name `.<file name>.<pid>.<counter>.tmp`.
fn temporary_pid(name: &str) -> Option<u32> {
    let rest = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let mut parts = rest.rsplitn(3, '.');
    let _counter: u64 = parts.next()?.parse().ok()?;
    let pid = parts.next()?.parse().ok()?;
    parts.next().filter(|file| !file.is_empty()).map(|_| pid)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_content_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.csv");
        write_atomic(&path, b"first").unwrap();
        write_atomic(&path, b"second").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("a.csv")]);
    }

    #[test]
    fn unchanged_content_is_not_rewritten() {
        use std::os::unix::fs::MetadataExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.csv");
        write_if_changed(&path, b"same").unwrap();
        let inode = std::fs::metadata(&path).unwrap().ino();
        write_if_changed(&path, b"same").unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().ino(), inode, "not replaced");
        write_if_changed(&path, b"other").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"other");
    }

    #[test]
    fn stale_temporaries_of_dead_processes_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        // Linux process ids stay below 2^22, so 999999999 is never alive.
        let dead = dir.path().join(".a.csv.999999999.0.tmp");
        let ours = dir.path().join(format!(".a.csv.{}.3.tmp", std::process::id()));
        let other = dir.path().join(".notes.tmp");
        for path in [&dead, &ours, &other] {
            std::fs::write(path, "partial").unwrap();
        }
        assert_eq!(remove_stale_temporaries(dir.path()).unwrap(), 1);
        assert!(!dead.exists() && ours.exists() && other.exists());
        assert_eq!(temporary_pid(".x.y.csv.12.7.tmp"), Some(12));
        assert_eq!(temporary_pid(".12.7.tmp"), None);
    }

    #[test]
    fn missing_folders_are_made_and_failure_names_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("new-dir").join("a.csv");
        write_atomic(&path, b"x").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"x");
        // A regular file where a folder should be.
        let blocked = dir.path().join("new-dir").join("a.csv").join("b.csv");
        let e = write_atomic(&blocked, b"x").unwrap_err().to_string();
        assert!(e.contains("a.csv"), "{e}");
    }
}
