//! `ndtgrid._core.FreeSpace`: cells crossed by laser beams, for occupancy
//! exports.

use std::sync::Mutex;

use ndt_core::{FreeSpace, Pose2};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;

use crate::convert::points;
use crate::errors::{poisoned, to_py};

/// `(image (H, W) int8, origin (2,))` as returned by `raster`.
type RasterArrays<'py> = (Bound<'py, PyArray2<i8>>, Bound<'py, PyArray1<f64>>);

#[doc = stub_doc!("FreeSpace")]
#[pyclass(name = "FreeSpace", module = "ndtgrid._core", frozen)]
pub struct PyFreeSpace {
    inner: Mutex<FreeSpace>,
}

impl PyFreeSpace {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, FreeSpace>> {
        self.inner.lock().map_err(|_| poisoned())
    }
}

#[pymethods]
impl PyFreeSpace {
    #[new]
    #[pyo3(signature = (resolution = 0.05))]
    fn new(resolution: f64) -> PyResult<Self> {
        Ok(Self {
            inner: Mutex::new(FreeSpace::new(resolution).map_err(to_py)?),
        })
    }

    #[doc = stub_doc!("FreeSpace.resolution")]
    #[getter]
    fn resolution(&self) -> PyResult<f64> {
        Ok(self.lock()?.resolution())
    }

    fn __len__(&self) -> PyResult<usize> {
        Ok(self.lock()?.len())
    }

    #[doc = stub_doc!("FreeSpace.add_scan")]
    fn add_scan(
        &self,
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        pose: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let pts = crate::convert::points(points, "points")?;
        let pairs = pts.as_pairs()?;
        let p = pose_arg(pose)?;
        py.detach(|| {
            self.lock()?
                .add_scan(pairs, Pose2::new(p[0], p[1], p[2]))
                .map_err(to_py)
        })
    }

    #[doc = stub_doc!("FreeSpace.raster")]
    #[pyo3(signature = (occupied, *, max_cells = 100_000_000))]
    fn raster<'py>(
        &self,
        py: Python<'py>,
        occupied: &Bound<'py, PyAny>,
        max_cells: u64,
    ) -> PyResult<RasterArrays<'py>> {
        let occ = points(occupied, "occupied")?;
        let pairs = occ.as_pairs()?;
        let r = py.detach(|| self.lock()?.raster(pairs, max_cells).map_err(to_py))?;
        let image = PyArray1::from_vec(py, r.data).reshape([r.height, r.width])?;
        Ok((image, PyArray1::from_slice(py, &r.origin)))
    }
}

fn pose_arg(obj: &Bound<'_, PyAny>) -> PyResult<[f64; 3]> {
    crate::convert::pose(obj, "pose")
}
