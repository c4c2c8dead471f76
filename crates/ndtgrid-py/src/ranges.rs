//! `ndtgrid.ranges_to_points`: laser ranges and beam angles to points.

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;

use crate::convert::vector;
use crate::errors::to_py;

#[doc = stub_doc!("ranges_to_points")]
#[pyfunction]
#[pyo3(signature = (ranges, angles, *, min_range = 0.0, max_range = f64::INFINITY))]
pub fn ranges_to_points<'py>(
    py: Python<'py>,
    ranges: &Bound<'py, PyAny>,
    angles: &Bound<'py, PyAny>,
    min_range: f64,
    max_range: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let r = vector(ranges, "ranges")?;
    let a = vector(angles, "angles")?;
    let (r, a) = (r.as_slice()?, a.as_slice()?);
    let pts = py
        .detach(|| ndt_core::points_from_ranges(r, a, min_range, max_range))
        .map_err(to_py)?;
    let n = pts.len();
    PyArray1::from_vec(py, pts.into_iter().flatten().collect()).reshape([n, 2])
}
