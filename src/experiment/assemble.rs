//! Finishing an experiment: unit files -> `<experiment>.csv` -> plots. It works on the files alone,
//! not on the row type, so a single run and a merge of shards produce the same bytes.

use std::path::{Path, PathBuf};

use super::error::ExperimentError;
use super::files::read;
use super::layout::ExperimentDir;
use super::name::SafeName;
use super::name::UnitKey;
use super::plot::{PlotKind, PlotSpec, calibration_labels, render_plot};
use super::spec::Manifest;
use crate::atomic::write_if_changed;

/// A unit file checked at the CSV level: a header, at least one record, every record as wide as the
/// header, UTF-8 throughout.
#[derive(Debug)]
pub(crate) struct UnitTable {
    /// The header line, with its terminator.
    pub header: Vec<u8>,
    pub columns: csv::StringRecord,
    /// Every line after the header, ending in a newline.
    pub body: Vec<u8>,
}

impl UnitTable {
    pub fn read(path: &Path) -> Result<Self, ExperimentError> {
        Self::parse(read(path)?, path)
    }

    pub fn parse(bytes: Vec<u8>, path: &Path) -> Result<Self, ExperimentError> {
        let corrupt = |what: String| ExperimentError::CorruptUnit {
            path: path.to_path_buf(),
            what,
        };
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(true)
            .from_reader(&bytes[..]);
        let columns = reader.headers().map_err(|e| corrupt(e.to_string()))?.clone();
        if columns.is_empty() || columns.iter().all(str::is_empty) {
            return Err(corrupt("no header".to_string()));
        }
        let body_start = reader.position().byte() as usize;
        let mut records = 0usize;
        for record in reader.records() {
            record.map_err(|e| corrupt(e.to_string()))?;
            records += 1;
        }
        if records == 0 {
            return Err(corrupt("no rows".to_string()));
        }
        let (header, body) = bytes.split_at(body_start.min(bytes.len()));
        let mut body = body.to_vec();
        if body.last() != Some(&b'\n') {
            body.push(b'\n');
        }
        Ok(Self {
            header: header.to_vec(),
            columns,
            body,
        })
    }
}

/// The keys of `manifest` whose unit file is not in `dir`.
pub fn missing_units<'m>(dir: &ExperimentDir, manifest: &'m Manifest) -> Vec<&'m UnitKey> {
    manifest
        .units
        .iter()
        .filter(|key| !dir.unit_csv(key).is_file())
        .collect()
}

/// The units of `manifest` whose file of detail table `table` is not in `dir`. Units saved before
/// their experiment had that table lack it.
pub fn missing_detail<'m>(dir: &ExperimentDir, manifest: &'m Manifest, table: &SafeName) -> Vec<&'m UnitKey> {
    manifest
        .units
        .iter()
        .filter(|key| !dir.detail_unit_csv(table, key).is_file())
        .collect()
}

/// The files an assembled experiment has.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finished {
    pub csv: PathBuf,
    /// `<experiment>_<table>.csv` of each detail table every unit has a file of, in the manifest's
    /// order.
    pub details: Vec<PathBuf>,
    /// The detail tables not assembled, each with the number of units that lack its file (saved by
    /// a build before the table existed).
    pub incomplete: Vec<(SafeName, usize)>,
    /// Each curve of the reliability diagrams, named with its ECE (`pf (ECE 0.042)`).
    pub calibration: Vec<String>,
    pub config: PathBuf,
    pub plots: Vec<PathBuf>,
}

/// Assembles `<experiment>.csv` from every unit file in manifest order (one header; every unit must
/// have the same header), each detail table likewise when every unit has its file, and draws the
/// manifest's plots (a plot of a detail table not assembled is skipped). Fails with
/// [`ExperimentError::Incomplete`] when a unit file is missing.
pub fn finish(dir: &ExperimentDir, manifest: &Manifest) -> Result<Finished, ExperimentError> {
    let missing = missing_units(dir, manifest);
    if let Some(first) = missing.first() {
        return Err(ExperimentError::Incomplete {
            experiment: dir.name().to_string(),
            dir: dir.root().to_path_buf(),
            missing: missing.len(),
            total: manifest.units.len(),
            first_missing: (*first).clone(),
        });
    }
    let csv = dir.csv();
    let units: Vec<PathBuf> = manifest.units.iter().map(|key| dir.unit_csv(key)).collect();
    write_if_changed(&csv, &concatenate(&units)?)?;
    let (mut details, mut incomplete) = (Vec::new(), Vec::new());
    for table in &manifest.details {
        let lacking = missing_detail(dir, manifest, table).len();
        if lacking > 0 {
            incomplete.push((table.clone(), lacking));
            continue;
        }
        let path = dir.detail_csv(table);
        let units: Vec<PathBuf> = manifest
            .units
            .iter()
            .map(|key| dir.detail_unit_csv(table, key))
            .collect();
        write_if_changed(&path, &concatenate(&units)?)?;
        details.push(path);
    }
    let (mut plots, mut calibration) = (Vec::new(), Vec::new());
    for spec in &manifest.spec.plots {
        let source = plot_source(dir, spec);
        if source == csv || details.contains(&source) {
            let (figure, paths) = render_plot(spec, &source, dir)?;
            plots.extend(paths);
            if spec.kind == PlotKind::Reliability {
                calibration.extend(calibration_labels(&figure));
            }
        }
    }
    Ok(Finished {
        csv,
        details,
        incomplete,
        calibration,
        config: dir.config(),
        plots,
    })
}

/// The assembled table `spec` draws: the main one, or the detail table it names.
pub(crate) fn plot_source(dir: &ExperimentDir, spec: &PlotSpec) -> PathBuf {
    match &spec.table {
        Some(table) => dir.detail_csv(table),
        None => dir.csv(),
    }
}

/// The unit files `paths` as one table: the first one's header, then every file's rows in order;
/// every file must have the same header.
pub(crate) fn concatenate(paths: &[PathBuf]) -> Result<Vec<u8>, ExperimentError> {
    let mut out: Vec<u8> = Vec::new();
    let mut first: Option<(UnitTable, &PathBuf)> = None;
    for path in paths {
        let table = UnitTable::read(path)?;
        match &first {
            None => {
                out.extend_from_slice(&table.header);
                out.extend_from_slice(&table.body);
                first = Some((table, path));
            }
            Some((head, head_path)) if head.columns != table.columns => {
                return Err(ExperimentError::CorruptUnit {
                    path: path.clone(),
                    what: format!(
                        "header '{}' differs from '{}' of {}",
                        table.columns.iter().collect::<Vec<_>>().join(","),
                        head.columns.iter().collect::<Vec<_>>().join(","),
                        head_path.display()
                    ),
                });
            }
            Some(_) => out.extend_from_slice(&table.body),
        }
    }
    Ok(out)
}
