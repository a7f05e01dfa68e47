//! What an experiment is on disk, apart from its rows: [`ExperimentSpec`] (name, description,
//! plots) and the [`Manifest`] that adds the ordered unit keys, so that `merge` and the index can
//! finish an experiment without its code.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::error::ExperimentError;
use super::files::read_json;
use super::name::{ExperimentName, SafeName, UnitKey};
use super::plot::PlotSpec;
use crate::atomic::{write_atomic, write_if_changed};

/// The name, a one-line description (shown in the results index) and the plots of an experiment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExperimentSpec {
    pub name: ExperimentName,
    pub description: String,
    pub plots: Vec<PlotSpec>,
}

/// `manifest.json`: the spec plus every unit key of the whole experiment (all shards), in the
/// experiment's order, which is the order of the assembled CSV.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    #[serde(flatten)]
    pub spec: ExperimentSpec,
    /// The experiment's further tables ([`super::unit::DetailTables::names`]), in order: absent in
    /// experiments without any and in manifests written before there were any; manifests written
    /// when there could be only one name it as `"detail": "<table>"`.
    #[serde(
        default,
        alias = "detail",
        deserialize_with = "one_or_many",
        skip_serializing_if = "Vec::is_empty"
    )]
    pub details: Vec<SafeName>,
    pub units: Vec<UnitKey>,
}

/// A table name or a list of them (see [`Manifest::details`]).
fn one_or_many<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<Vec<SafeName>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum OneOrMany {
        One(SafeName),
        Many(Vec<SafeName>),
    }
    Ok(match OneOrMany::deserialize(deserializer)? {
        OneOrMany::One(name) => vec![name],
        OneOrMany::Many(names) => names,
    })
}

impl Manifest {
    pub fn read(path: &Path) -> Result<Self, ExperimentError> {
        read_json(path)
    }

    /// Pretty JSON with a final newline; the same manifest always gives the same bytes.
    pub fn to_json(&self, path: &Path) -> Result<Vec<u8>, ExperimentError> {
        to_json(self, path)
    }
}

/// `value` as pretty JSON with a final newline; `path` names the destination in errors.
pub fn to_json<T: Serialize + ?Sized>(value: &T, path: &Path) -> Result<Vec<u8>, ExperimentError> {
    let mut bytes = serde_json::to_vec_pretty(value).map_err(|e| ExperimentError::Json {
        path: path.to_path_buf(),
        what: e.to_string(),
    })?;
    bytes.push(b'\n');
    Ok(bytes)
}

/// Writes `bytes` to `path` unless the file exists; an existing file must hold exactly `bytes`,
/// because a resumed run that changed its units or configuration would mix results.
/// `what` says what differs ("configuration"); `dir` is what to delete instead.
pub fn write_or_check(
    path: &Path,
    bytes: &[u8],
    dir: &Path,
    what: &'static str,
) -> Result<(), ExperimentError> {
    if !check_unchanged(path, bytes, dir, what)? {
        write_atomic(path, bytes)?;
    }
    Ok(())
}

/// ` (fields: a, b.c)`: the paths of the JSON fields in which `earlier` and `now` differ (at most
/// five), or nothing when either is not JSON, so that a refusal says which setting changed.
fn differing_fields(earlier: &[u8], now: &[u8]) -> String {
    fn walk(a: &serde_json::Value, b: &serde_json::Value, at: &str, out: &mut Vec<String>) {
        match (a, b) {
            (serde_json::Value::Object(x), serde_json::Value::Object(y)) => {
                let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
                for key in keys {
                    let null = serde_json::Value::Null;
                    let path = if at.is_empty() {
                        key.clone()
                    } else {
                        format!("{at}.{key}")
                    };
                    walk(
                        x.get(key).unwrap_or(&null),
                        y.get(key).unwrap_or(&null),
                        &path,
                        out,
                    );
                }
            }
            _ if a != b => out.push(if at.is_empty() {
                "the whole file".into()
            } else {
                at.into()
            }),
            _ => {}
        }
    }
    let (Ok(a), Ok(b)) = (
        serde_json::from_slice::<serde_json::Value>(earlier),
        serde_json::from_slice::<serde_json::Value>(now),
    ) else {
        return String::new();
    };
    let mut fields = Vec::new();
    walk(&a, &b, "", &mut fields);
    match fields.len() {
        0 => String::new(),
        n if n > 5 => format!(" (fields: {}, and {} more)", fields[..5].join(", "), n - 5),
        _ => format!(" (fields: {})", fields.join(", ")),
    }
}

/// Whether `path` exists holding exactly `bytes` (`false`: it does not exist); an error when it
/// holds anything else (see [`write_or_check`]).
pub fn check_unchanged(
    path: &Path,
    bytes: &[u8],
    dir: &Path,
    what: &'static str,
) -> Result<bool, ExperimentError> {
    match std::fs::read(path) {
        Ok(existing) if existing == bytes => Ok(true),
        Ok(existing) => Err(ExperimentError::ChangedSinceLastRun {
            path: path.to_path_buf(),
            dir: dir.to_path_buf(),
            what,
            differing: differing_fields(&existing, bytes),
        }),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(false),
        Err(source) => Err(ExperimentError::Io {
            path: path.to_path_buf(),
            source,
        }),
    }
}

/// Writes `manifest` (serialised as `bytes`) to `path`. An existing manifest must list the same
/// units in the same order, since the unit files on disk belong to it; its description and plots
/// may change, and are replaced.
pub fn write_manifest(
    path: &Path,
    manifest: &Manifest,
    bytes: &[u8],
    dir: &Path,
) -> Result<(), ExperimentError> {
    if path.exists() && Manifest::read(path)?.units != manifest.units {
        return Err(ExperimentError::ChangedSinceLastRun {
            path: path.to_path_buf(),
            dir: dir.to_path_buf(),
            what: "units",
            differing: String::new(),
        });
    }
    Ok(write_if_changed(path, bytes)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_changed_configuration_names_its_fields() {
        let dir = tempfile::tempdir().expect("a temporary folder");
        let path = dir.path().join("config.json");
        let earlier = br#"{"seed": 1, "real": {"path": "a.csv", "rows": 6}, "scale": 0.1}"#;
        write_or_check(&path, earlier, dir.path(), "configuration").expect("the first run writes it");
        assert!(write_or_check(&path, earlier, dir.path(), "configuration").is_ok());
        let now = br#"{"seed": 1, "real": {"path": "b.csv", "rows": 8}, "scale": 0.1, "extra": true}"#;
        let e = write_or_check(&path, now, dir.path(), "configuration").expect_err("a changed run");
        assert!(
            e.to_string()
                .contains("different configuration (fields: extra, real.path, real.rows)"),
            "{e}"
        );
        let many: Vec<String> = (0..7).map(|i| format!("\"f{i}\": {i}")).collect();
        let many = format!("{{{}}}", many.join(", "));
        let e = write_or_check(&path, many.as_bytes(), dir.path(), "configuration").expect_err("changed");
        assert!(e.to_string().contains("and 5 more)"), "{e}");
        assert_eq!(differing_fields(b"not json", b"{}"), "");
    }
}
