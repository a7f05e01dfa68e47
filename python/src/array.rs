//! numpy arrays in and out, through numpy's own buffer functions (no compiled numpy API, so one
//! abi3 wheel serves every numpy and Python from 3.9), and JSON values out as `json.loads` makes
//! them.

use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyTuple};

use crate::error::bad_argument;

/// A new writable array of `shape` holding `values` (f64), converted to `dtype`.
pub fn from_f64<'py>(
    py: Python<'py>,
    values: &[f64],
    shape: &[usize],
    dtype: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let numpy = py.import("numpy")?;
    let flat = numpy.call_method1("frombuffer", (PyByteArray::new(py, &bytes), "<f8"))?;
    flat.call_method1("reshape", (PyTuple::new(py, shape)?,))?
        .call_method1("astype", (dtype,))
}

/// A new array of strings (numpy's unicode dtype), one per item.
pub fn strings<'py>(py: Python<'py>, items: Vec<String>) -> PyResult<Bound<'py, PyAny>> {
    py.import("numpy")?.call_method1("array", (items, "U"))
}

/// A new int64 array.
pub fn from_i64<'py>(py: Python<'py>, values: Vec<i64>) -> PyResult<Bound<'py, PyAny>> {
    py.import("numpy")?.call_method1("array", (values, "<i8"))
}

/// Any array-like of numbers as a C-ordered f64 array: its shape and its values.
pub fn to_f64(value: &Bound<'_, PyAny>, name: &str) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let numpy = value.py().import("numpy")?;
    let array = numpy
        .call_method1("ascontiguousarray", (value, "<f8"))
        .map_err(|e| bad_argument(name, format!("not an array of numbers ({e})")))?;
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    let bytes: Vec<u8> = array.call_method0("tobytes")?.extract()?;
    let values = bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
        .collect();
    Ok((shape, values))
}

/// A JSON value as the Python value `json.loads` makes of it.
pub fn json_to_python(py: Python<'_>, value: &serde_json::Value) -> PyResult<Py<PyAny>> {
    Ok(py
        .import("json")?
        .call_method1("loads", (value.to_string(),))?
        .unbind())
}
