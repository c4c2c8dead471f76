//! SE(2) helpers on `[x, y, theta]` arrays, so that Python code composes
//! poses with the core's own arithmetic (eq. 2) instead of its own.

use ndt_core::Pose2;
use numpy::PyArray1;
use pyo3::prelude::*;

use crate::convert::{pose, vec3};

fn arg(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Pose2> {
    let p = pose(obj, what)?;
    Ok(Pose2::new(p[0], p[1], p[2]))
}

#[doc = stub_doc!("compose")]
#[pyfunction]
pub fn compose<'py>(
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    Ok(vec3(a.py(), arg(a, "a")?.compose(arg(b, "b")?).to_array()))
}

#[doc = stub_doc!("inverse")]
#[pyfunction]
pub fn inverse<'py>(p: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<f64>>> {
    Ok(vec3(p.py(), arg(p, "p")?.inverse().to_array()))
}

#[doc = stub_doc!("between")]
#[pyfunction]
pub fn between<'py>(
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    Ok(vec3(a.py(), arg(a, "a")?.between(arg(b, "b")?).to_array()))
}
