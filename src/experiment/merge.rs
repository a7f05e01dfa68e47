//! Combining shard outputs: `taction merge DIRS... --out DIR` gives exactly the files one unsharded
//! run would have written.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::assemble::{Finished, UnitTable, finish};
use super::error::ExperimentError;
use super::files::{create_dir_all, read};
use super::index::write_index;
use super::layout::{ExperimentDir, experiments_in};
use super::name::{ExperimentName, UnitKey};
use super::spec::{Manifest, write_manifest, write_or_check};
use crate::atomic::{remove_stale_temporaries, write_atomic};

/// What a merge produced, per experiment in name order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MergeReport {
    pub experiments: Vec<(ExperimentName, Finished)>,
    /// Unit files copied into the output (units already there with identical bytes are not counted).
    pub copied: usize,
}

/// Merges the output roots `inputs` (each the `--out` of one or more shard runs) into `out`, which
/// may be one of them.
///
/// For every experiment found (a directory holding `manifest.json`): its `manifest.json` and
/// `config.json` must be byte-identical in every input that has it (else
/// [`ExperimentError::ShardMismatch`] names the two directories); every unit file is checked and
/// copied (a unit present in several inputs must be identical, else
/// [`ExperimentError::UnitConflict`]); then the experiment is assembled and plotted, which fails with
/// [`ExperimentError::Incomplete`] if some unit is in no input. Finally the index is rewritten.
pub fn merge(inputs: &[PathBuf], out: &Path) -> Result<MergeReport, ExperimentError> {
    let mut experiments: BTreeMap<ExperimentName, Vec<ExperimentDir>> = BTreeMap::new();
    for input in inputs {
        let found = experiments_in(input)?;
        if found.is_empty() {
            return Err(ExperimentError::NoExperiments { dir: input.clone() });
        }
        for dir in found {
            experiments.entry(dir.name().clone()).or_default().push(dir);
        }
    }
    let mut report = MergeReport {
        experiments: Vec::new(),
        copied: 0,
    };
    for (name, sources) in &experiments {
        let (finished, copied) = merge_experiment(name, sources, out)?;
        report.experiments.push((name.clone(), finished));
        report.copied += copied;
    }
    write_index(out)?;
    Ok(report)
}

fn merge_experiment(
    name: &ExperimentName,
    sources: &[ExperimentDir],
    out: &Path,
) -> Result<(Finished, usize), ExperimentError> {
    let first = &sources[0];
    let manifest_bytes = read(&first.manifest())?;
    let config_bytes = read(&first.config())?;
    let manifest = Manifest::read(&first.manifest())?;
    if &manifest.spec.name != name {
        return Err(ExperimentError::Json {
            path: first.manifest(),
            what: format!(
                "names experiment '{}' but lies in directory '{name}'",
                manifest.spec.name
            ),
        });
    }
    for other in &sources[1..] {
        for (file, path, bytes) in [
            ("manifest.json", other.manifest(), &manifest_bytes),
            ("config.json", other.config(), &config_bytes),
        ] {
            if &read(&path)? != bytes {
                return Err(ExperimentError::ShardMismatch {
                    experiment: name.to_string(),
                    file,
                    first: first.root().to_path_buf(),
                    second: other.root().to_path_buf(),
                });
            }
        }
    }

    let target = ExperimentDir::new(out, name);
    let mut folders = vec![out.to_path_buf(), target.root().to_path_buf(), target.units_dir()];
    folders.extend(
        manifest
            .details
            .iter()
            .map(|table| target.detail_units_dir(table)),
    );
    for folder in &folders {
        create_dir_all(folder)?;
        remove_stale_temporaries(folder)?;
    }
    write_manifest(&target.manifest(), &manifest, &manifest_bytes, target.root())?;
    write_or_check(&target.config(), &config_bytes, target.root(), "configuration")?;
    let copied = copy_units(&manifest, sources, &target)?;
    Ok((finish(&target, &manifest)?, copied))
}

/// Copies every unit's files (its rows and each detail table's) found among `sources` into
/// `target`; how many it wrote.
fn copy_units(
    manifest: &Manifest,
    sources: &[ExperimentDir],
    target: &ExperimentDir,
) -> Result<usize, ExperimentError> {
    let mut copied = 0;
    for key in &manifest.units {
        let files = |dir: &ExperimentDir| {
            let details = manifest
                .details
                .iter()
                .map(|table| dir.detail_unit_csv(table, key));
            std::iter::once(dir.unit_csv(key))
                .chain(details)
                .collect::<Vec<_>>()
        };
        let sources: Vec<Vec<PathBuf>> = sources.iter().map(files).collect();
        for (i, dest) in files(target).into_iter().enumerate() {
            let paths: Vec<&PathBuf> = sources.iter().map(|s| &s[i]).collect();
            copied += usize::from(copy_unit_file(key, &paths, &dest)?);
        }
    }
    Ok(copied)
}

/// Copies the unit file of `key` found among `sources` (which must agree where several have it) to
/// `dest` (which must agree if it exists); whether it wrote `dest`. A file in no source is skipped.
fn copy_unit_file(key: &UnitKey, sources: &[&PathBuf], dest: &Path) -> Result<bool, ExperimentError> {
    let mut chosen: Option<(Vec<u8>, PathBuf)> = None;
    for &path in sources {
        if !path.is_file() {
            continue;
        }
        let bytes = read(path)?;
        match &chosen {
            Some((kept, kept_path)) if kept != &bytes => {
                return Err(ExperimentError::UnitConflict {
                    key: key.clone(),
                    first: kept_path.clone(),
                    second: path.clone(),
                });
            }
            Some(_) => {}
            None => {
                UnitTable::parse(bytes.clone(), path)?;
                chosen = Some((bytes, path.clone()));
            }
        }
    }
    let Some((bytes, path)) = chosen else {
        return Ok(false);
    };
    match std::fs::read(dest) {
        Ok(existing) if existing == bytes => Ok(false),
        Ok(_) => Err(ExperimentError::UnitConflict {
            key: key.clone(),
            first: path,
            second: dest.to_path_buf(),
        }),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            write_atomic(dest, &bytes)?;
            Ok(true)
        }
        Err(source) => Err(ExperimentError::Io {
            path: dest.to_path_buf(),
            source,
        }),
    }
}
