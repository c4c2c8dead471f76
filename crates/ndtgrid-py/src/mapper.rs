//! `ndtgrid.Mapper`: the NDT grid with the §V elimination in front of it.
//!
//! The grid is shared with the `ndtgrid.NdtGrid` handed out by `grid`
//! (one `Arc<RwLock<NdtGrid>>`); the filter state sits in its own lock. Locks
//! are taken with the GIL released, the grid's first, always in that order.

use std::path::PathBuf;
use std::sync::{Arc, Mutex, RwLock};

use ndt_core::{MapFilter, NdtGrid, Pose2};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyType};

use crate::convert::vector;
use crate::errors::{poisoned, to_py};
use crate::grid::{PyNdtGrid, Reduced};
use crate::mapper_options::PyMapperOptions;
use crate::small_object::{PyRemovalCounts, PySmallObject};

#[doc = stub_doc!("Mapper")]
#[pyclass(name = "Mapper", module = "ndtgrid._core", frozen)]
pub struct PyMapper {
    grid: Arc<RwLock<NdtGrid>>,
    filter: Mutex<MapFilter>,
    grid_handle: Py<PyNdtGrid>,
    options: Py<PyMapperOptions>,
}

impl PyMapper {
    /// Runs `f` on the grid and the filter state, both locked for reading
    /// (the filter has one lock mode), with the GIL released.
    fn with_both<T: Send>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&NdtGrid, &MapFilter) -> T + Send,
    ) -> PyResult<T> {
        py.detach(|| {
            let grid = self.grid.read().map_err(|_| ())?;
            let filter = self.filter.lock().map_err(|_| ())?;
            Ok(f(&grid, &filter))
        })
        .map_err(|()| poisoned())
    }

    /// Runs `f` on the grid and the filter state, both locked for writing.
    fn with_both_mut<T: Send>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&mut NdtGrid, &mut MapFilter) -> T + Send,
    ) -> PyResult<T> {
        py.detach(|| {
            let mut grid = self.grid.write().map_err(|_| ())?;
            let mut filter = self.filter.lock().map_err(|_| ())?;
            Ok(f(&mut grid, &mut filter))
        })
        .map_err(|()| poisoned())
    }
}

impl PyMapper {
    /// A Python mapper holding `mapper` (a copy handed out by another object).
    pub(crate) fn from_core(py: Python<'_>, mapper: ndt_core::Mapper) -> PyResult<Self> {
        let (grid, filter) = mapper.into_parts();
        Self::from_parts(py, grid, filter)
    }

    /// A Python mapper of a grid and a filter state (e.g. loaded from a file).
    fn from_parts(py: Python<'_>, grid: NdtGrid, filter: MapFilter) -> PyResult<Self> {
        let options = Py::new(py, PyMapperOptions::from(*filter.options()))?;
        let grid = Arc::new(RwLock::new(grid));
        let grid_handle = Py::new(py, PyNdtGrid::shared(Arc::clone(&grid)))?;
        Ok(Self {
            grid,
            filter: Mutex::new(filter),
            grid_handle,
            options,
        })
    }
}

#[pymethods]
impl PyMapper {
    #[new]
    #[pyo3(signature = (cell_size = 0.02, *, outlier_filter = true, **options))]
    fn new(
        py: Python<'_>,
        cell_size: f64,
        outlier_filter: bool,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let kwargs = match options {
            Some(d) => d.copy()?,
            None => PyDict::new(py),
        };
        kwargs.set_item("outlier_filter", outlier_filter)?;
        let opts: Bound<'_, PyMapperOptions> = py
            .get_type::<PyMapperOptions>()
            .call((), Some(&kwargs))?
            .cast_into()?;
        let filter = MapFilter::new(opts.get().core()).map_err(to_py)?;
        let grid = Arc::new(RwLock::new(NdtGrid::new(cell_size).map_err(to_py)?));
        let grid_handle = Py::new(py, PyNdtGrid::shared(Arc::clone(&grid)))?;
        Ok(Self {
            grid,
            filter: Mutex::new(filter),
            grid_handle,
            options: opts.unbind(),
        })
    }

    #[doc = stub_doc!("Mapper.grid")]
    #[getter]
    fn grid(&self, py: Python<'_>) -> Py<PyNdtGrid> {
        self.grid_handle.clone_ref(py)
    }

    #[doc = stub_doc!("Mapper.options")]
    #[getter]
    fn options(&self, py: Python<'_>) -> Py<PyMapperOptions> {
        self.options.clone_ref(py)
    }

    #[doc = stub_doc!("Mapper.cell_size")]
    #[getter]
    fn cell_size(&self, py: Python<'_>) -> PyResult<f64> {
        self.with_both(py, |g, _| g.cell_size())
    }

    #[doc = stub_doc!("Mapper.scan_count")]
    #[getter]
    fn scan_count(&self, py: Python<'_>) -> PyResult<u64> {
        self.with_both(py, |_, f| f.scans())
    }

    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.with_both(py, |g, _| g.len())
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let on = self.options.get().core().outlier_filter;
        self.with_both(py, |g, f| {
            format!(
                "Mapper(cell_size={}, outlier_filter={}, scans={}, cells={})",
                g.cell_size(),
                if on { "True" } else { "False" },
                f.scans(),
                g.len()
            )
        })
    }

    #[doc = stub_doc!("Mapper.insert_scan")]
    fn insert_scan(
        &self,
        py: Python<'_>,
        ranges: &Bound<'_, PyAny>,
        angles: &Bound<'_, PyAny>,
        pose: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let r = vector(ranges, "ranges")?;
        let a = vector(angles, "angles")?;
        let (r, a) = (r.as_slice()?, a.as_slice()?);
        let p = crate::convert::pose(pose, "pose")?;
        let at = Pose2 {
            x: p[0],
            y: p[1],
            theta: p[2],
        };
        self.with_both_mut(py, |g, f| f.insert_scan(g, r, a, at))?
            .map_err(to_py)
    }

    #[doc = stub_doc!("Mapper.occupied_cells")]
    fn occupied_cells<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let flat = self.with_both(py, |g, _| {
            let s = g.cell_size();
            let mut keys: Vec<_> = g.keys().collect();
            keys.sort_unstable();
            keys.iter()
                .flat_map(|k| {
                    let c = k.center(s);
                    [c.x, c.y]
                })
                .collect::<Vec<f64>>()
        })?;
        let k = flat.len() / 2;
        PyArray1::from_vec(py, flat).reshape([k, 2])
    }

    #[doc = stub_doc!("Mapper.small_objects")]
    fn small_objects(&self, py: Python<'_>) -> PyResult<Vec<PySmallObject>> {
        self.with_both(py, |g, f| {
            let s = g.cell_size();
            f.small_objects(g)
                .iter()
                .map(|o| PySmallObject::new(o, s))
                .collect()
        })
    }

    #[doc = stub_doc!("Mapper.removal_counts")]
    fn removal_counts(&self, py: Python<'_>) -> PyResult<PyRemovalCounts> {
        self.with_both(py, |_, f| PyRemovalCounts::from(f.removal_counts()))
    }

    #[doc = stub_doc!("Mapper.run_checks")]
    fn run_checks(&self, py: Python<'_>) -> PyResult<usize> {
        self.with_both_mut(py, |g, f| f.run_checks(g))
    }

    #[doc = stub_doc!("Mapper.to_bytes")]
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = self
            .with_both(py, ndt_core::persist::mapper_to_bytes)?
            .map_err(to_py)?;
        Ok(PyBytes::new(py, &bytes))
    }

    #[doc = stub_doc!("Mapper.from_bytes")]
    #[classmethod]
    fn from_bytes(_cls: &Bound<'_, PyType>, py: Python<'_>, data: &[u8]) -> PyResult<Self> {
        let (grid, filter) = py
            .detach(|| ndt_core::persist::mapper_from_bytes(data))
            .map_err(to_py)?;
        Self::from_parts(py, grid, filter)
    }

    #[doc = stub_doc!("Mapper.save")]
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let bytes = self
            .with_both(py, ndt_core::persist::mapper_to_bytes)?
            .map_err(to_py)?;
        py.detach(|| ndt_core::persist::write_atomic(&path, &bytes))
            .map_err(to_py)
    }

    #[doc = stub_doc!("Mapper.load")]
    #[classmethod]
    fn load(_cls: &Bound<'_, PyType>, py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let (grid, filter) = py
            .detach(|| ndt_core::persist::load_mapper_parts(&path))
            .map_err(to_py)?;
        Self::from_parts(py, grid, filter)
    }

    /// Pickle (and `copy`) through the file format's bytes.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Reduced<'py>> {
        let from_bytes = py.get_type::<Self>().getattr("from_bytes")?;
        Ok((from_bytes, (self.to_bytes(py)?,)))
    }
}
