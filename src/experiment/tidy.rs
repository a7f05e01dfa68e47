//! The tidy rows of the recognition tables, each declared once ([`tidy_row!`]): its leading
//! columns, the curve's factor columns ([`Factors`], one per thing the experiment varies), its
//! trailing columns.
//!
//! A derive cannot write these rows: the factor columns are known only at run time (one per
//! factor of the experiment, none in some), and serde's derive takes a struct's fields as they
//! are. Written by hand, each row spelt its columns in its `Serialize` and again, if read back, in
//! its `Deserialize`, eight times over; here the struct is the one list and both directions follow
//! from it, cell by cell ([`WriteCell`], [`ReadCell`]). A row is read back by column name from its
//! [`Cells`], its factor columns being those between its last leading and its first trailing one.

use std::fmt;
use std::str::FromStr;

use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::ser::{SerializeStruct, Serializer};
use serde::{Deserialize, Serialize};

use super::factor::{Factor, FactorError, Factors};

/// A row of a tidy table, written column by column into a CSV record.
pub(crate) trait TidyRecord {
    /// The number of columns, its factor columns and any named at run time counted.
    fn width(&self) -> usize;

    /// The columns in order, into a record that may add its own after them (`active` does).
    fn serialize_columns<S: SerializeStruct>(&self, row: &mut S) -> Result<(), S::Error>;
}

/// `record` as one serde struct named `name`: the `Serialize` of every tidy row.
pub(crate) fn serialize_record<R: TidyRecord, S: Serializer>(
    name: &'static str,
    record: &R,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    let mut row = serializer.serialize_struct(name, record.width())?;
    record.serialize_columns(&mut row)?;
    row.end()
}

/// The row `read` makes of one CSV record: the `Deserialize` of every tidy row read back.
pub(crate) fn deserialize_record<'de, D: Deserializer<'de>, R>(
    deserializer: D,
    read: impl FnOnce(&Cells) -> Result<R, String>,
) -> Result<R, D::Error> {
    let cells = Cells::deserialize(deserializer)?;
    read(&cells).map_err(de::Error::custom)
}

/// A value that fills one cell of a tidy row, as the tables have always written it: a number by
/// serde's CSV writer, an absent number as an empty cell, a yes/no as 0 or 1.
pub(crate) trait WriteCell {
    fn write_cell<S: SerializeStruct>(&self, row: &mut S, column: &'static str) -> Result<(), S::Error>;
}

/// A value read back from the cell of its column, refused with the column named.
pub(crate) trait ReadCell: Sized {
    fn read_cell(cells: &Cells, column: &str) -> Result<Self, String>;
}

macro_rules! plain_cells {
    ($($t:ty),+) => {$(
        impl WriteCell for $t {
            fn write_cell<S: SerializeStruct>(&self, row: &mut S, column: &'static str) -> Result<(), S::Error> {
                row.serialize_field(column, self)
            }
        }
    )+};
}
plain_cells!(String, u32, u64, i64, usize, f64);

macro_rules! number_cells {
    ($($t:ty),+) => {$(
        impl ReadCell for $t {
            fn read_cell(cells: &Cells, column: &str) -> Result<Self, String> {
                cells.number(column)
            }
        }
    )+};
}
number_cells!(u32, u64, i64, usize, f64);

/// Empty when `None`.
impl<T: Serialize> WriteCell for Option<T> {
    fn write_cell<S: SerializeStruct>(&self, row: &mut S, column: &'static str) -> Result<(), S::Error> {
        row.serialize_field(column, self)
    }
}

/// `None` when the cell is empty.
impl<T: FromStr> ReadCell for Option<T> {
    fn read_cell(cells: &Cells, column: &str) -> Result<Self, String> {
        cells.optional_number(column)
    }
}

/// 1 or 0, which every CSV reader takes as a number.
impl WriteCell for bool {
    fn write_cell<S: SerializeStruct>(&self, row: &mut S, column: &'static str) -> Result<(), S::Error> {
        row.serialize_field(column, &u8::from(*self))
    }
}

impl ReadCell for bool {
    fn read_cell(cells: &Cells, column: &str) -> Result<Self, String> {
        match cells.number::<u8>(column)? {
            0 => Ok(false),
            1 => Ok(true),
            other => Err(format!("column '{column}': {other} is not 0 or 1")),
        }
    }
}

impl ReadCell for String {
    fn read_cell(cells: &Cells, column: &str) -> Result<Self, String> {
        cells.text(column)
    }
}

/// Declares a tidy row once: the struct, its [`TidyRecord`] and `Serialize`, and, when it ends in
/// `impl Deserialize;`, `from_cells` (the row read by column name, columns after its own left for
/// the caller) and `Deserialize`.
///
/// The fields are the columns in order, each named as its column: the leading ones, then the field
/// marked `#[factors]` (a [`Factors`], one column per factor), then the trailing ones, then
/// optionally a field marked `#[columns_named_at_run_time]` (`Vec<(String, f64)>`, written after
/// the rest; such a row is not read back). Each cell is written by its type's [`WriteCell`] and
/// read by its [`ReadCell`], in column order, so the first bad cell is the one reported.
///
/// ```ignore
/// tidy_row! {
///     /// One point of one curve.
///     #[derive(Debug, Clone, PartialEq)]
///     pub struct AttemptRow {
///         pub experiment: String,
///         pub descriptor: String,
///         #[factors]
///         pub factors: Factors,
///         pub trial: u32,
///         pub accuracy: f64,
///     }
///     impl Deserialize;
/// }
/// ```
macro_rules! tidy_row {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $(pub $lead:ident: $lead_ty:ty,)+
            #[factors]
            pub $factors:ident: Factors,
            $(pub $trail:ident: $trail_ty:ty,)+
        }
        impl Deserialize;
    ) => {
        $crate::experiment::tidy::tidy_row! {
            $(#[$meta])*
            pub struct $name {
                $(pub $lead: $lead_ty,)+
                #[factors]
                pub $factors: Factors,
                $(pub $trail: $trail_ty,)+
            }
        }

        impl $name {
            /// The row in `cells`, read by column name; columns after its own are left there.
            pub(crate) fn from_cells(cells: &$crate::experiment::tidy::Cells) -> Result<Self, String> {
                use $crate::experiment::tidy::ReadCell;
                $(let $lead = <$lead_ty as ReadCell>::read_cell(cells, stringify!($lead))?;)+
                let $factors = cells.factors_between(
                    &[$(stringify!($lead)),+],
                    &[$(stringify!($trail)),+],
                )?;
                $(let $trail = <$trail_ty as ReadCell>::read_cell(cells, stringify!($trail))?;)+
                Ok(Self {
                    $($lead,)+
                    $factors,
                    $($trail,)+
                })
            }
        }

        impl<'de> ::serde::Deserialize<'de> for $name {
            fn deserialize<D: ::serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
                $crate::experiment::tidy::deserialize_record(deserializer, Self::from_cells)
            }
        }
    };
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $(pub $lead:ident: $lead_ty:ty,)+
            #[factors]
            pub $factors:ident: Factors,
            $(pub $trail:ident: $trail_ty:ty,)+
            $(#[columns_named_at_run_time] pub $named:ident: Vec<(String, f64)>,)?
        }
    ) => {
        $(#[$meta])*
        pub struct $name {
            $(pub $lead: $lead_ty,)+
            pub $factors: $crate::experiment::factor::Factors,
            $(pub $trail: $trail_ty,)+
            $(pub $named: Vec<(String, f64)>,)?
        }

        impl $crate::experiment::tidy::TidyRecord for $name {
            fn width(&self) -> usize {
                [$(stringify!($lead),)+ $(stringify!($trail),)+].len()
                    + self.$factors.len()
                    $(+ self.$named.len())?
            }

            fn serialize_columns<S: ::serde::ser::SerializeStruct>(&self, row: &mut S) -> Result<(), S::Error> {
                use $crate::experiment::tidy::WriteCell;
                $(self.$lead.write_cell(row, stringify!($lead))?;)+
                self.$factors.serialize_columns(row)?;
                $(self.$trail.write_cell(row, stringify!($trail))?;)+
                $(for (column, value) in &self.$named {
                    row.serialize_field($crate::experiment::tidy::static_name(column), value)?;
                })?
                Ok(())
            }
        }

        impl ::serde::Serialize for $name {
            fn serialize<S: ::serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                $crate::experiment::tidy::serialize_record(stringify!($name), self, serializer)
            }
        }
    };
}
pub(crate) use tidy_row;

/// A column name as the `&'static str` serde's struct fields take: a column named at run time is
/// leaked once per distinct name (a handful per process).
pub(crate) fn static_name(column: &str) -> &'static str {
    use std::collections::BTreeSet;
    use std::sync::Mutex;
    static NAMES: Mutex<BTreeSet<&'static str>> = Mutex::new(BTreeSet::new());
    let mut names = NAMES.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some(&name) = names.get(column) {
        return name;
    }
    let name: &'static str = Box::leak(column.to_string().into_boxed_str());
    names.insert(name);
    name
}

/// One CSV record as (column, cell) pairs in header order: what the tidy rows are read from, since
/// their factor columns are known only from the header.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Cells {
    cells: Vec<(String, String)>,
}

impl Cells {
    fn cell(&self, column: &str) -> Result<&str, String> {
        self.cells
            .iter()
            .find(|(c, _)| c == column)
            .map(|(_, v)| v.as_str())
            .ok_or_else(|| format!("no column '{column}'"))
    }

    pub(crate) fn text(&self, column: &str) -> Result<String, String> {
        self.cell(column).map(str::to_string)
    }

    pub(crate) fn number<T: FromStr>(&self, column: &str) -> Result<T, String> {
        let text = self.cell(column)?;
        text.parse().map_err(|_| {
            format!(
                "column '{column}': '{text}' is not a {}",
                std::any::type_name::<T>()
            )
        })
    }

    /// The cell of `column` as a number, `None` when it is empty.
    pub(crate) fn optional_number<T: FromStr>(&self, column: &str) -> Result<Option<T>, String> {
        match self.cell(column)? {
            "" => Ok(None),
            _ => self.number(column).map(Some),
        }
    }

    /// The columns after the last of `leading` and before the first of `trailing` (`descriptor`
    /// and `trial`, or `bin` in a reliability table), each a [`Factor`] with a valid level.
    pub(crate) fn factors_between(&self, leading: &[&str], trailing: &[&str]) -> Result<Factors, String> {
        let position = |column: &str| {
            self.cells
                .iter()
                .position(|(c, _)| c == column)
                .ok_or_else(|| format!("no column '{column}'"))
        };
        let first = match leading.last() {
            Some(last) => position(last)? + 1,
            None => 0,
        };
        let end = match trailing.first() {
            Some(next) => position(next)?,
            None => self.cells.len(),
        };
        let factors = Factors::new(
            self.cells
                .get(first..end)
                .unwrap_or_default()
                .iter()
                .map(|(column, level)| {
                    Factor::from_column(column)
                        .map(|f| (f, level.clone()))
                        .ok_or_else(|| FactorError::Unknown {
                            column: column.clone(),
                        })
                })
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| e.to_string())?,
        );
        factors.check().map_err(|e| e.to_string())?;
        Ok(factors)
    }
}

impl<'de> Deserialize<'de> for Cells {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Visit;
        impl<'de> Visitor<'de> for Visit {
            type Value = Cells;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a CSV record with a header")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Cells, A::Error> {
                let mut cells = Vec::new();
                while let Some((column, cell)) = map.next_entry::<String, String>()? {
                    cells.push((column, cell));
                }
                Ok(Cells { cells })
            }
        }
        deserializer.deserialize_map(Visit)
    }
}
