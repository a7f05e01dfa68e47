//! Arguments as Python passes them, parsed at the edge into what the library takes: a whole number
//! that may not be negative, and the objects to touch as a list or a set's name. A value that is
//! not one is a `TactionError` saying what it got (PyO3 adds a note naming the argument), not
//! Python's `OverflowError` or a `TypeError` about Rust types.

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyString};

use crate::error::refused;
use crate::object::{Object, objects};

/// A value as Python prints it (`repr`), for a refusal's message.
fn shown(obj: pyo3::Borrowed<'_, '_, PyAny>) -> String {
    obj.repr().map(|r| r.to_string()).unwrap_or_else(|_| "?".into())
}

/// A count, an index or a seed: a Python `int` from 0 to the type's largest value. A signature's
/// default is then `Whole(1)`, which PyO3 shows as `...`, so those signatures spell out their
/// `text_signature`.
pub struct Whole<T>(pub T);

macro_rules! whole {
    ($t:ty) => {
        impl<'a, 'py> FromPyObject<'a, 'py> for Whole<$t> {
            type Error = PyErr;

            fn extract(obj: pyo3::Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
                let refusal = || {
                    refused(format!(
                        "{} is not a whole number from 0 to {}",
                        shown(obj),
                        <$t>::MAX
                    ))
                };
                // Python's bool is an int; True as a count is a slip, not a 1.
                if obj.is_instance_of::<PyBool>() {
                    return Err(refusal());
                }
                obj.extract::<$t>().map(Whole).map_err(|_| refusal())
            }
        }
    };
}

whole!(usize);
whole!(u64);

/// The objects to touch: a list of `taction.Object`s, or a set's name or folder as
/// `taction.objects` takes it (built into objects here).
pub struct Objects(pub Vec<Arc<taction::mesh::Object>>);

impl<'a, 'py> FromPyObject<'a, 'py> for Objects {
    type Error = PyErr;

    fn extract(obj: pyo3::Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let py = obj.py();
        let is_path =
            obj.is_instance_of::<PyString>() || obj.is_instance(&py.import("os")?.getattr("PathLike")?)?;
        if is_path {
            let set: PathBuf = obj.extract()?;
            return Ok(Self(
                objects(py, set, None)?.into_iter().map(|o| o.inner).collect(),
            ));
        }
        let list: Vec<PyRef<'_, Object>> = obj.extract().map_err(|_| {
            refused(format!(
                "{} is neither a list of taction.Object nor a set's name or folder",
                shown(obj)
            ))
        })?;
        Ok(Self(list.iter().map(|o| Arc::clone(&o.inner)).collect()))
    }
}

/// `start_pose` (`StartPose::NAMES`) within `start_heading_deg` of the canonical heading.
pub fn start_pose(name: &str, start_heading_deg: f64) -> PyResult<taction::sim::StartPose> {
    let heading = max_heading(start_heading_deg)?;
    taction::sim::StartPose::parse(name, heading).ok_or_else(|| {
        crate::error::bad_argument(
            "start_pose",
            format!(
                "'{name}' is none of {}",
                taction::sim::StartPose::NAMES.join(", ")
            ),
        )
    })
}

/// `start_heading_deg`, how far from its canonical heading an object may stand: 0 to 180 degrees.
pub fn max_heading(start_heading_deg: f64) -> PyResult<taction::sim::MaxHeading> {
    taction::sim::MaxHeading::from_deg(start_heading_deg).ok_or_else(|| {
        crate::error::bad_argument(
            "start_heading_deg",
            format!("{start_heading_deg} is outside [0, 180]"),
        )
    })
}

/// `perturb_deg` / `perturb_frac` (Sec. V-B4's bounds) moved by `perturb_by`
/// (`PerturbationAct::NAMES`: the paper's teleport, or a push).
pub fn perturbation(
    perturb_deg: f64,
    perturb_frac: f64,
    perturb_by: &str,
) -> PyResult<taction::sim::PerturbationBounds> {
    let act = taction::sim::PerturbationAct::from_name(perturb_by).ok_or_else(|| {
        crate::error::bad_argument(
            "perturb_by",
            format!(
                "'{perturb_by}' is not one of {}",
                taction::sim::PerturbationAct::NAMES.join(", ")
            ),
        )
    })?;
    Ok(taction::sim::PerturbationBounds::new(perturb_deg, perturb_frac)
        .map_err(refused)?
        .by(act))
}
