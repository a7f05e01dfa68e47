//! Files of the experiment framework read and folders made, each naming its path on failure.
//! Writing goes through the crate's one atomic writer, [`crate::atomic`].

use std::path::Path;

use super::error::ExperimentError;

/// Creates `dir` and its parents, naming `dir` on failure (e.g. an unwritable output root).
pub fn create_dir_all(dir: &Path) -> Result<(), ExperimentError> {
    std::fs::create_dir_all(dir).map_err(ExperimentError::io(dir))
}

/// Reads a whole file, naming it on failure.
pub fn read(path: &Path) -> Result<Vec<u8>, ExperimentError> {
    std::fs::read(path).map_err(ExperimentError::io(path))
}

/// Reads a JSON file as `T`, naming it on failure.
pub fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, ExperimentError> {
    serde_json::from_slice(&read(path)?).map_err(|e| ExperimentError::Json {
        path: path.to_path_buf(),
        what: e.to_string(),
    })
}
