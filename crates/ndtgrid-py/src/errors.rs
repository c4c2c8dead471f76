//! The one place where core errors become Python exceptions.

use ndt_core::NdtError;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::PyErr;

/// Every [`NdtError`] but a failed file operation and a lost or absent
/// mapper is bad input: a `ValueError` carrying the core's message, which
/// names the argument (or the file), what was expected and what came. A failed file
/// operation is an `OSError` with the error number, so that Python picks the
/// subclass (`FileNotFoundError`, `IsADirectoryError`, ...), and the file
/// name. An odometry's mapper that lost scans across a fork, or asked of a
/// loop that builds none, and a helper thread of `match_many` that panicked
/// (a bug) are a `RuntimeError`: nothing the call passed was wrong.
pub fn to_py(err: NdtError) -> PyErr {
    match err {
        NdtError::Io {
            path,
            action,
            errno: Some(errno),
            message,
        } => PyOSError::new_err((errno, format!("cannot {action}: {message}"), path)),
        NdtError::Io { .. } => PyOSError::new_err(err.to_string()),
        NdtError::MapperLost { .. } | NdtError::NoMap | NdtError::ThreadPanicked { .. } => {
            PyRuntimeError::new_err(err.to_string())
        }
        other => PyValueError::new_err(other.to_string()),
    }
}

/// A lock left poisoned by an internal panic: the map may be inconsistent, so
/// say so rather than hand out possibly half-updated data.
pub fn poisoned() -> PyErr {
    PyRuntimeError::new_err(
        "ndtgrid: the map was poisoned by an earlier internal error; rebuild it",
    )
}
