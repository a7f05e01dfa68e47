//! Where an experiment's files live under the output root:
//!
//! ```text
//! <out>/README.md                      index of every experiment (see `index`)
//! <out>/<experiment>/manifest.json     name, description, plots, the ordered unit keys
//! <out>/<experiment>/config.json       the run's full configuration
//! <out>/<experiment>/units/<key>.csv   one unit's rows, header first
//! <out>/<experiment>/<experiment>.csv  all rows, units in manifest order, one header
//! <out>/<experiment>/<stem>.svg|.png   the plots
//! ```

use std::path::{Path, PathBuf};

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

    /// The assembled table, `<experiment>.csv`.
    pub fn csv(&self) -> PathBuf {
        self.root.join(format!("{}.csv", self.name))
    }

    /// A plot file, `<stem>.<extension>`.
    pub fn plot(&self, stem: &SafeName, extension: &str) -> PathBuf {
        self.root.join(format!("{stem}.{extension}"))
    }
}
