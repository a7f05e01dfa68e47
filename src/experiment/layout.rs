//! Where an experiment's files live under the output root:
//!
//! ```text
//! <out>/README.md                      index of every experiment (see `index`)
//! <out>/<experiment>/manifest.json     name, description, plots, the ordered unit keys
//! <out>/<experiment>/config.json       the run's full configuration
//! <out>/<experiment>/units/<key>.csv   one unit's rows, header first
//! <out>/<experiment>/units/<table>/<key>.csv   one unit's detail rows (experiments with further
//!                                      tables, e.g. `per_object`, `reliability`)
//! <out>/<experiment>/<experiment>.csv  all rows, units in manifest order, one header
//! <out>/<experiment>/<experiment>_<table>.csv  all detail rows, likewise
//! <out>/<experiment>/<stem>.svg|.png   the plots
//! ```

use std::path::{Path, PathBuf};

use super::error::ExperimentError;
use super::name::{ExperimentName, SafeName, UnitKey};

/// The file names of one experiment's output directory.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExperimentDir {
    root: PathBuf,
    name: ExperimentName,
}

impl ExperimentDir {
    pub fn new(out: &Path, name: &ExperimentName) -> Self {
        Self {
            root: out.join(name.as_str()),
            name: name.clone(),
        }
    }

    pub fn root(&self) -> &Path {
        &self.root
    }

    pub fn name(&self) -> &ExperimentName {
        &self.name
    }

    pub fn manifest(&self) -> PathBuf {
        self.root.join("manifest.json")
    }

    pub fn config(&self) -> PathBuf {
        self.root.join("config.json")
    }

    pub fn units_dir(&self) -> PathBuf {
        self.root.join("units")
    }

    pub fn unit_csv(&self, key: &UnitKey) -> PathBuf {
        self.units_dir().join(format!("{key}.csv"))
    }

    /// The folder of a detail table's unit files, `units/<table>`.
    pub fn detail_units_dir(&self, table: &SafeName) -> PathBuf {
        self.units_dir().join(table.as_str())
    }

    pub fn detail_unit_csv(&self, table: &SafeName, key: &UnitKey) -> PathBuf {
        self.detail_units_dir(table).join(format!("{key}.csv"))
    }

    /// The assembled table, `<experiment>.csv`.
    pub fn csv(&self) -> PathBuf {
        self.root.join(format!("{}.csv", self.name))
    }

    /// The assembled detail table, `<experiment>_<table>.csv`.
    pub fn detail_csv(&self, table: &SafeName) -> PathBuf {
        self.root.join(format!("{}_{table}.csv", self.name))
    }

    /// A plot file, `<stem>.<extension>`.
    pub fn plot(&self, stem: &SafeName, extension: &str) -> PathBuf {
        self.root.join(format!("{stem}.{extension}"))
    }
}

/// The experiment directories directly under `root`, in name order.
pub(crate) fn experiments_in(root: &Path) -> Result<Vec<ExperimentDir>, ExperimentError> {
    Ok(folders_holding(root, "manifest.json")?
        .iter()
        .map(|name| ExperimentDir::new(root, name))
        .collect())
}

/// The sub-folders of `root` with a safe name that hold a file `file`, sorted by name.
pub(crate) fn folders_holding(root: &Path, file: &str) -> Result<Vec<SafeName>, ExperimentError> {
    let mut names = Vec::new();
    for entry in std::fs::read_dir(root).map_err(ExperimentError::io(root))? {
        let entry = entry.map_err(ExperimentError::io(root))?;
        let file_name = entry.file_name();
        let Some(name) = file_name.to_str().and_then(|n| SafeName::new(n).ok()) else {
            continue;
        };
        if entry.path().join(file).is_file() {
            names.push(name);
        }
    }
    names.sort();
    Ok(names)
}
