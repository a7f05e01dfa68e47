//! One exception for everything the library refuses, carrying the library's own message (the file,
//! line or field at fault and what is wrong), as the CLI prints it.

use pyo3::PyErr;
use pyo3::create_exception;
use pyo3::exceptions::PyException;

create_exception!(
    taction,
    TactionError,
    PyException,
    "What taction refused: a broken mesh, a malformed file, an out-of-range parameter. The message names the file, line or field at fault."
);

/// The library's error as a `TactionError` with its message.
pub fn refused(e: impl std::fmt::Display) -> PyErr {
    TactionError::new_err(e.to_string())
}

/// A `TactionError` naming the argument at fault.
pub fn bad_argument(name: &str, what: impl std::fmt::Display) -> PyErr {
    TactionError::new_err(format!("{name}: {what}"))
}
