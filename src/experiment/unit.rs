//! Work units: the resumable pieces of an experiment, and their row files.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use serde::Serialize;
use serde::de::DeserializeOwned;

use super::error::ExperimentError;
use super::name::UnitKey;

/// Any error a unit's work can return.
pub type BoxError = Box<dyn std::error::Error + Send + Sync>;

type Work<'a, R, D> = dyn Fn() -> Result<(Vec<R>, <D as DetailTables>::Rows), BoxError> + Send + Sync + 'a;

/// The rows of one of an experiment's further tables, finer than its main rows (the recognition
/// experiments' per-object outcomes and reliability tables beside their averaged accuracy). Each
/// unit writes them to `units/<TABLE>/<key>.csv` before its main file, so a unit whose main file
/// exists has them all, and they are assembled into `<experiment>_<TABLE>.csv`.
pub trait DetailRow: Serialize + DeserializeOwned {
    /// The table's name; `None` for an experiment without a second table.
    const TABLE: Option<&'static str>;
}

/// The detail rows of an experiment that has none.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum NoDetail {}

impl DetailRow for NoDetail {
    const TABLE: Option<&'static str> = None;
}

/// The further tables of an experiment: none ([`NoDetail`]), one ([`DetailRow`] `D`, whose rows are
/// `Vec<D>`), two (`(D, E)`, whose rows are `(Vec<D>, Vec<E>)`), three (`(D, E, F)`) or four.
pub trait DetailTables {
    /// What a unit's work gives besides its main rows.
    type Rows;
    /// The tables' names, in order.
    fn names() -> Vec<&'static str>;
    /// Each table's rows as CSV, in [`names`](Self::names) order, once they read back from it
    /// (`paths` name the destinations); the name of a table without rows is an error.
    fn encode(rows: &Self::Rows, paths: &[PathBuf]) -> Result<Vec<Vec<u8>>, String>;
}

impl<D: DetailRow> DetailTables for D {
    type Rows = Vec<D>;

    fn names() -> Vec<&'static str> {
        D::TABLE.into_iter().collect()
    }

    fn encode(rows: &Vec<D>, paths: &[PathBuf]) -> Result<Vec<Vec<u8>>, String> {
        match (D::TABLE, paths) {
            (Some(table), [path]) => Ok(vec![encode_table(table, rows, path)?]),
            _ => Ok(Vec::new()),
        }
    }
}

impl<D: DetailRow, E: DetailRow> DetailTables for (D, E) {
    type Rows = (Vec<D>, Vec<E>);

    fn names() -> Vec<&'static str> {
        D::TABLE.into_iter().chain(E::TABLE).collect()
    }

    fn encode((d, e): &(Vec<D>, Vec<E>), paths: &[PathBuf]) -> Result<Vec<Vec<u8>>, String> {
        let mut tables = D::encode(d, paths.get(..1).unwrap_or_default())?;
        tables.extend(E::encode(e, paths.get(tables.len()..).unwrap_or_default())?);
        Ok(tables)
    }
}

impl<D: DetailRow, E: DetailRow, F: DetailRow> DetailTables for (D, E, F) {
    type Rows = (Vec<D>, Vec<E>, Vec<F>);

    fn names() -> Vec<&'static str> {
        <(D, E)>::names().into_iter().chain(F::TABLE).collect()
    }

    fn encode((d, e, f): &(Vec<D>, Vec<E>, Vec<F>), paths: &[PathBuf]) -> Result<Vec<Vec<u8>>, String> {
        let mut tables = D::encode(d, paths.get(..1).unwrap_or_default())?;
        let next = tables.len();
        tables.extend(E::encode(e, paths.get(next..next + 1).unwrap_or_default())?);
        tables.extend(F::encode(f, paths.get(tables.len()..).unwrap_or_default())?);
        Ok(tables)
    }
}

impl<D: DetailRow, E: DetailRow, F: DetailRow, G: DetailRow> DetailTables for (D, E, F, G) {
    type Rows = (Vec<D>, Vec<E>, Vec<F>, Vec<G>);

    fn names() -> Vec<&'static str> {
        <(D, E, F)>::names().into_iter().chain(G::TABLE).collect()
    }

    fn encode((d, e, f, g): &Self::Rows, paths: &[PathBuf]) -> Result<Vec<Vec<u8>>, String> {
        let mut tables = D::encode(d, paths.get(..1).unwrap_or_default())?;
        let next = tables.len();
        tables.extend(E::encode(e, paths.get(next..next + 1).unwrap_or_default())?);
        let next = tables.len();
        tables.extend(F::encode(f, paths.get(next..next + 1).unwrap_or_default())?);
        tables.extend(G::encode(g, paths.get(tables.len()..).unwrap_or_default())?);
        Ok(tables)
    }
}

/// `rows` of `table` as CSV for `path`, once they read back: a header and every row (so rows must
/// be structs with named fields, not tuples or scalars); no rows is an error.
pub(crate) fn encode_table<R: Serialize + DeserializeOwned>(
    table: &str,
    rows: &[R],
    path: &Path,
) -> Result<Vec<u8>, String> {
    if rows.is_empty() {
        return Err(format!("produced no {table} rows"));
    }
    let bytes = rows_to_csv(rows, path).map_err(|e| e.to_string())?;
    match parse_rows::<R>(&bytes, path) {
        Ok(back) if back.len() == rows.len() => Ok(bytes),
        _ => Err(
            "its rows do not read back from CSV: rows must be structs of plain fields (names become the header)"
                .to_string(),
        ),
    }
}

/// One resumable piece of an experiment: a stable key and the work producing its rows (and, for an
/// experiment with further tables ([`DetailTables`]), their rows).
///
/// The rows must be a deterministic function of what the closure captured (settings and a seed
/// derived from the run seed, e.g. with [`crate::rng::stream`]), never of the thread or the order in
/// which units run: that is what makes `--threads`, `--shard` and resuming give identical files.
/// `R` is a struct whose field names become the CSV header.
pub struct Unit<'a, R, D: DetailTables = NoDetail> {
    key: UnitKey,
    work: Box<Work<'a, R, D>>,
}

impl<'a, R: 'a> Unit<'a, R, NoDetail> {
    pub fn new(key: UnitKey, work: impl Fn() -> Result<Vec<R>, BoxError> + Send + Sync + 'a) -> Self {
        Self {
            key,
            work: Box::new(move || Ok((work()?, Vec::new()))),
        }
    }
}

impl<'a, R, D: DetailTables> Unit<'a, R, D> {
    /// A unit whose work gives its rows and its detail rows (one `Vec` per table, a pair of them
    /// for two tables).
    pub fn with_detail(
        key: UnitKey,
        work: impl Fn() -> Result<(Vec<R>, D::Rows), BoxError> + Send + Sync + 'a,
    ) -> Self {
        Self {
            key,
            work: Box::new(work),
        }
    }

    pub fn key(&self) -> &UnitKey {
        &self.key
    }

    /// Runs the work; a panic inside it becomes an error naming the unit, so one bad unit does not
    /// take down the units running beside it.
    pub(crate) fn run(&self) -> Result<(Vec<R>, D::Rows), String> {
        match catch_unwind(AssertUnwindSafe(|| (self.work)())) {
            Ok(Ok((rows, _))) if rows.is_empty() => Err("produced no rows".to_string()),
            Ok(Ok(rows)) => Ok(rows),
            Ok(Err(e)) => Err(e.to_string()),
            Err(panic) => Err(format!(
                "panicked: {}",
                panic
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "(no message)".to_string())
            )),
        }
    }
}

/// `rows` as CSV: a header line of field names, then one line per row; floats in shortest
/// round-trip form, so reading them back gives the same values bit for bit.
pub fn rows_to_csv<R: Serialize>(rows: &[R], path: &Path) -> Result<Vec<u8>, ExperimentError> {
    let csv_err = |e: csv::Error| ExperimentError::Csv {
        path: path.to_path_buf(),
        what: e.to_string(),
    };
    let mut writer = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    for row in rows {
        writer.serialize(row).map_err(csv_err)?;
    }
    writer.into_inner().map_err(|e| ExperimentError::Csv {
        path: path.to_path_buf(),
        what: e.to_string(),
    })
}

/// Reads a unit file as rows of `R`; any problem makes it a corrupt file, named with the line.
pub fn read_rows<R: DeserializeOwned>(path: &Path) -> Result<Vec<R>, ExperimentError> {
    let bytes = std::fs::read(path).map_err(ExperimentError::io(path))?;
    parse_rows(&bytes, path)
}

/// Parses unit-file bytes as rows of `R` (header first, at least one row); `path` names them in errors.
pub fn parse_rows<R: DeserializeOwned>(bytes: &[u8], path: &Path) -> Result<Vec<R>, ExperimentError> {
    let corrupt = |what: String| ExperimentError::CorruptUnit {
        path: path.to_path_buf(),
        what,
    };
    let mut reader = csv::Reader::from_reader(bytes);
    let rows = reader
        .deserialize()
        .collect::<Result<Vec<R>, _>>()
        .map_err(|e| corrupt(e.to_string()))?;
    if rows.is_empty() {
        return Err(corrupt("no rows".to_string()));
    }
    Ok(rows)
}
