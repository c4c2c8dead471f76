//! The one place where core errors become Python exceptions.

use ndt_core::NdtError;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::PyErr;

/// Every [`NdtError`] is bad input: a `ValueError` carrying the core's message,
/// which names the argument, what was expected and what came.
pub fn to_py(err: NdtError) -> PyErr {
    PyValueError::new_err(err.to_string())
}

/// A lock left poisoned by an internal panic: the map may be inconsistent, so
/// say so rather than hand out possibly half-updated data.
pub fn poisoned() -> PyErr {
    PyRuntimeError::new_err(
        "ndtgrid: the map was poisoned by an earlier internal error; rebuild it",
    )
}
