//! `ndtgrid.SmallObject` and `ndtgrid.RemovalCounts`: small frozen records
//! returned by `ndtgrid.Mapper`.

use ndt_core::{RemovalCounts, SmallObject};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};

use crate::record::reduce;

record! {
    #[doc = stub_doc!("SmallObject")]
    #[pyclass(name = "SmallObject", module = "ndtgrid._core", frozen)]
    pub struct PySmallObject(ObjectState) {
        center: [f64; 2],
        cells: Vec<f64>,
        #[pyo3(get)]
        num_points: u64,
    }
}

impl PySmallObject {
    /// From the core's object, with cell centres for cells of `cell_size` m.
    pub(crate) fn new(o: &SmallObject, cell_size: f64) -> Self {
        let cells = o
            .cells
            .iter()
            .flat_map(|k| {
                let c = k.center(cell_size);
                [c.x, c.y]
            })
            .collect();
        Self {
            center: [o.center.x, o.center.y],
            cells,
            num_points: o.points,
        }
    }
}

#[pymethods]
impl PySmallObject {
    /// `(2,)` centre of mass \[m\].
    #[getter]
    fn center<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.center)
    }

    /// `(K, 2)` centres of its cells \[m\].
    #[getter]
    fn cells<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        PyArray1::from_slice(py, &self.cells).reshape([self.cells.len() / 2, 2])
    }

    #[doc = stub_doc!("SmallObject.__reduce__")]
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (ObjectState,))> {
        reduce(slf, slf.get().state())
    }

    /// The object `__reduce__` took apart.
    #[classmethod]
    fn _restore(_cls: &Bound<'_, PyType>, state: ObjectState) -> Self {
        Self::from_state(state)
    }

    fn __repr__(&self) -> String {
        format!(
            "SmallObject(center=[{:.4}, {:.4}], cells={}, num_points={})",
            self.center[0],
            self.center[1],
            self.cells.len() / 2,
            self.num_points
        )
    }
}

#[doc = stub_doc!("RemovalCounts")]
#[pyclass(name = "RemovalCounts", module = "ndtgrid._core", frozen)]
pub struct PyRemovalCounts {
    inner: RemovalCounts,
}

impl From<RemovalCounts> for PyRemovalCounts {
    fn from(inner: RemovalCounts) -> Self {
        Self { inner }
    }
}

#[pymethods]
impl PyRemovalCounts {
    #[getter]
    fn behind_com_points(&self) -> u64 {
        self.inner.behind_com_points
    }
    #[getter]
    fn behind_com_cells(&self) -> u64 {
        self.inner.behind_com_cells
    }
    #[getter]
    fn forefront_points(&self) -> u64 {
        self.inner.forefront_points
    }
    #[getter]
    fn forefront_cells(&self) -> u64 {
        self.inner.forefront_cells
    }
    #[getter]
    fn area1_cells(&self) -> u64 {
        self.inner.area1_cells
    }
    #[getter]
    fn backshift_points(&self) -> u64 {
        self.inner.backshift_points
    }
    #[getter]
    fn backshift_cells(&self) -> u64 {
        self.inner.backshift_cells
    }
    #[getter]
    fn observation_cells(&self) -> u64 {
        self.inner.observation_cells
    }
    #[getter]
    fn confirmation_cells(&self) -> u64 {
        self.inner.confirmation_cells
    }

    #[doc = stub_doc!("RemovalCounts.as_dict")]
    fn as_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in self.inner.entries() {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    #[doc = stub_doc!("RemovalCounts.__reduce__")]
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, ([u64; 9],))> {
        reduce(slf, slf.get().inner.entries().map(|(_, v)| v))
    }

    /// The counts `__reduce__` took apart.
    #[classmethod]
    fn _restore(_cls: &Bound<'_, PyType>, counts: [u64; 9]) -> Self {
        let [behind_com_points, behind_com_cells, forefront_points, forefront_cells, area1_cells, backshift_points, backshift_cells, observation_cells, confirmation_cells] =
            counts;
        Self::from(RemovalCounts {
            behind_com_points,
            behind_com_cells,
            forefront_points,
            forefront_cells,
            area1_cells,
            backshift_points,
            backshift_cells,
            observation_cells,
            confirmation_cells,
        })
    }

    fn __repr__(&self) -> String {
        let parts: Vec<String> = self
            .inner
            .entries()
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect();
        format!("RemovalCounts({})", parts.join(", "))
    }
}
