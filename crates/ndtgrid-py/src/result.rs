//! `ndtgrid.MatchResult`: a small frozen record of one match.

use ndt_core::MatchResult;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyType;

use crate::convert::{mat3, rows, vec3};
use crate::record::reduce;

record! {
    #[doc = stub_doc!("MatchResult")]
    #[pyclass(name = "MatchResult", module = "ndtgrid._core", frozen)]
    pub struct PyMatchResult(State) {
        pose: [f64; 3],
        #[pyo3(get)]
        converged: bool,
        #[pyo3(get)]
        iterations: u32,
        #[pyo3(get)]
        score: f64,
        #[pyo3(get)]
        num_matched: usize,
        hessian: [[f64; 3]; 3],
        covariance: [[f64; 3]; 3],
        unconstrained: Vec<[f64; 3]>,
    }
}

impl From<MatchResult> for PyMatchResult {
    fn from(r: MatchResult) -> Self {
        Self {
            pose: r.pose.to_array(),
            converged: r.converged,
            iterations: r.iterations,
            score: r.score,
            num_matched: r.num_matched,
            hessian: rows(&r.hessian),
            covariance: rows(&r.covariance),
            unconstrained: r.unconstrained,
        }
    }
}

#[pymethods]
impl PyMatchResult {
    /// `(3,)` best pose `[x, y, theta]` of the scan in the map frame.
    #[getter]
    fn pose<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec3(py, self.pose)
    }

    /// `(3, 3)` Hessian of −E at `pose`.
    #[getter]
    fn hessian<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        mat3(py, self.hessian)
    }

    /// `(3, 3)` pose covariance estimate.
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        mat3(py, self.covariance)
    }

    /// `(K, 3)` pose directions `(dx, dy, dtheta)` the scan does not constrain.
    #[getter]
    fn unconstrained<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let k = self.unconstrained.len();
        PyArray1::from_vec(py, self.unconstrained.as_flattened().to_vec()).reshape([k, 3])
    }

    /// `True` when some pose direction is unconstrained.
    #[getter]
    fn degenerate(&self) -> bool {
        !self.unconstrained.is_empty()
    }

    #[doc = stub_doc!("MatchResult.__reduce__")]
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (State,))> {
        reduce(slf, slf.get().state())
    }

    /// The result `__reduce__` took apart.
    #[classmethod]
    fn _restore(_cls: &Bound<'_, PyType>, state: State) -> Self {
        Self::from_state(state)
    }

    fn __repr__(&self) -> String {
        let [x, y, t] = self.pose;
        format!(
            "MatchResult(pose=[{x:.6}, {y:.6}, {t:.6}], converged={}, iterations={}, \
             score={:.3}, num_matched={}, degenerate={})",
            if self.converged { "True" } else { "False" },
            self.iterations,
            self.score,
            self.num_matched,
            if self.unconstrained.is_empty() {
                "False"
            } else {
                "True"
            }
        )
    }
}
