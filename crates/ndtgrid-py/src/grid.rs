//! `ndtgrid.NdtGrid`: the sparse NDT grid map of §III-B and its matcher.
//!
//! Concurrency: the grid sits behind a read-write lock taken with the GIL
//! released, so many threads can `match` at once while `insert` is exclusive.
//! The lock is reference counted so that an `ndtgrid.Mapper` and the
//! `NdtGrid` it hands out (`mapper.grid`) are one and the same map.

use std::path::PathBuf;
use std::sync::{Arc, RwLock};

use ndt_core::{MatchOptions, NdtGrid, Pose2};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyType};

use crate::convert::{
    count, level_mask, mat3, point_sets, points, pose, poses, rows, vec3, Points,
};
use crate::errors::{poisoned, to_py};
use crate::match_options::options_from_kwargs;
use crate::result::PyMatchResult;

/// `(score, gradient, hessian, num_matched)` as returned by `evaluate`.
type Terms<'py> = (
    f64,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
    usize,
);
/// `(centres, counts)` as returned by `cells`.
type Cells<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<i64>>);

#[doc = stub_doc!("NdtGrid")]
#[pyclass(name = "NdtGrid", module = "ndtgrid._core", frozen)]
pub struct PyNdtGrid {
    inner: Arc<RwLock<NdtGrid>>,
}

impl From<NdtGrid> for PyNdtGrid {
    fn from(grid: NdtGrid) -> Self {
        Self {
            inner: Arc::new(RwLock::new(grid)),
        }
    }
}

impl PyNdtGrid {
    /// A Python handle on a grid shared with its owner (the mapper).
    pub(crate) fn shared(inner: Arc<RwLock<NdtGrid>>) -> Self {
        Self { inner }
    }

    fn read<T>(&self, py: Python<'_>, f: impl FnOnce(&NdtGrid) -> T + Send) -> PyResult<T>
    where
        T: Send,
    {
        py.detach(|| {
            let grid = self.inner.read().map_err(|_| ())?;
            Ok(f(&grid))
        })
        .map_err(|()| poisoned())
    }

    /// `f` on the grid under its write lock, with the GIL released (the
    /// inserts: matches wait for them, see `read`).
    fn write<T>(&self, py: Python<'_>, f: impl FnOnce(&mut NdtGrid) -> T + Send) -> PyResult<T>
    where
        T: Send,
    {
        py.detach(|| {
            let mut grid = self.inner.write().map_err(|_| ())?;
            Ok(f(&mut grid))
        })
        .map_err(|()| poisoned())
    }
}

#[pymethods]
impl PyNdtGrid {
    #[new]
    #[pyo3(signature = (cell_size = 0.02, *, levels = 6))]
    fn new(cell_size: f64, levels: i64) -> PyResult<Self> {
        let levels = count("levels", levels)? as usize;
        Ok(Self {
            inner: Arc::new(RwLock::new(
                NdtGrid::with_levels(cell_size, levels).map_err(to_py)?,
            )),
        })
    }

    #[doc = stub_doc!("NdtGrid.levels")]
    #[getter]
    fn levels(&self, py: Python<'_>) -> PyResult<usize> {
        self.read(py, NdtGrid::levels)
    }

    #[doc = stub_doc!("NdtGrid.cell_size")]
    #[getter]
    fn cell_size(&self, py: Python<'_>) -> PyResult<f64> {
        self.read(py, NdtGrid::cell_size)
    }

    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.read(py, NdtGrid::len)
    }

    #[doc = stub_doc!("NdtGrid.memory_bytes")]
    #[getter]
    fn memory_bytes(&self, py: Python<'_>) -> PyResult<usize> {
        self.read(py, NdtGrid::heap_bytes)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        self.read(py, |g| {
            format!("NdtGrid(cell_size={}, cells={})", g.cell_size(), g.len())
        })
    }

    #[doc = stub_doc!("NdtGrid.insert")]
    fn insert(
        &self,
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        pose: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let pts = points_arg(points)?;
        let pairs = pts.as_pairs()?;
        let p = crate::convert::pose(pose, "pose")?;
        // The changed keys are dropped inside, without the GIL.
        self.write(py, |grid| {
            grid.insert(pairs, Pose2::new(p[0], p[1], p[2])).map(|_| ())
        })?
        .map_err(to_py)
    }

    #[doc = stub_doc!("NdtGrid.insert_many")]
    fn insert_many(
        &self,
        py: Python<'_>,
        scans: &Bound<'_, PyAny>,
        poses: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let arrays = point_sets(scans, "scans", "insert")?;
        let pairs = Points::all_pairs(&arrays)?;
        // Angles wrapped as `insert` wraps them (its inserts, bit for bit).
        let poses: Vec<Pose2> = crate::convert::poses(poses, "poses")?
            .into_iter()
            .map(|[x, y, theta]| Pose2::new(x, y, theta))
            .collect();
        self.write(py, |grid| grid.insert_many(&pairs, &poses))?
            .map_err(to_py)
    }

    #[doc = stub_doc!("NdtGrid.match")]
    #[pyo3(name = "match", signature = (
        points, guess, *, expansion = 10.0, sigma_floor = 0.02, shape_cell = 0.32, neighbor_search = true, fuse_minority = true,
        pair_neighbors = false, search_radius = 1, max_iterations = 50, translation_tolerance = 1e-4,
        rotation_tolerance = 1e-4, max_step_cells = 2.0, max_step_rotation = 0.05, rotation_search = 0.15, rotation_gate = 0.9, freeze_unconstrained = true, freeze_ratio = 0.1,
        levels = None,
        skip_levels = None,
        coarse_model = true,
        expansion_phases = None,
        parallel = false
    ), text_signature = "($self, points, guess, *, expansion=10.0, sigma_floor=0.02, \
        shape_cell=0.32, neighbor_search=True, fuse_minority=True, pair_neighbors=False, \
        search_radius=1, max_iterations=50, translation_tolerance=1e-4, rotation_tolerance=1e-4, \
        max_step_cells=2.0, max_step_rotation=0.05, rotation_search=0.15, rotation_gate=0.9, \
        freeze_unconstrained=True, freeze_ratio=0.1, levels=None, skip_levels=None, \
        coarse_model=True, expansion_phases=None, parallel=False)")]
    #[allow(clippy::too_many_arguments)]
    fn match_scan(
        &self,
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        guess: &Bound<'_, PyAny>,
        expansion: f64,
        sigma_floor: f64,
        shape_cell: f64,
        neighbor_search: bool,
        fuse_minority: bool,
        pair_neighbors: bool,
        search_radius: i64,
        max_iterations: i64,
        translation_tolerance: f64,
        rotation_tolerance: f64,
        max_step_cells: f64,
        max_step_rotation: f64,
        rotation_search: f64,
        rotation_gate: f64,
        freeze_unconstrained: bool,
        freeze_ratio: f64,
        levels: Option<i64>,
        skip_levels: Option<Vec<i64>>,
        coarse_model: bool,
        expansion_phases: Option<Vec<f64>>,
        parallel: bool,
    ) -> PyResult<PyMatchResult> {
        let options = MatchOptions {
            expansion,
            sigma_floor,
            shape_cell,
            neighbor_search,
            search_radius: count("search_radius", search_radius)?,
            fuse_minority,
            pair_neighbors,
            max_iterations: count("max_iterations", max_iterations)?,
            translation_tolerance,
            rotation_tolerance,
            max_step_cells,
            max_step_rotation,
            rotation_search,
            rotation_gate,
            freeze_unconstrained,
            freeze_ratio,
            levels: levels.map(|l| count("levels", l)).transpose()?,
            // `None`: the default (the signature shows it).
            skip_levels: level_mask(
                "skip_levels",
                skip_levels.as_deref(),
                MatchOptions::default().skip_levels,
            )?,
            coarse_model,
            parallel,
        };
        let pts = points_arg(points)?;
        let pairs = pts.as_pairs()?;
        let g = pose(guess, "guess")?;
        let guess = Pose2 {
            x: g[0],
            y: g[1],
            theta: g[2],
        };
        self.read(py, |grid| match &expansion_phases {
            Some(phases) => grid.match_phased(pairs, guess, &options, phases),
            None => grid.match_scan(pairs, guess, &options),
        })?
        .map(PyMatchResult::from)
        .map_err(to_py)
    }

    #[doc = stub_doc!("NdtGrid.match_many")]
    #[pyo3(signature = (scans, guesses, *, threads = None, **options))]
    fn match_many(
        &self,
        py: Python<'_>,
        scans: &Bound<'_, PyAny>,
        guesses: &Bound<'_, PyAny>,
        threads: Option<i64>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Vec<PyMatchResult>> {
        let (options, phases) = options_from_kwargs("match_many", options)?;
        let threads = threads
            .map(|t| count("threads", t).map(|t| t as usize))
            .transpose()?;
        let arrays = point_sets(scans, "scans", "match")?;
        let pairs = Points::all_pairs(&arrays)?;
        let guesses: Vec<Pose2> = poses(guesses, "guesses")?
            .into_iter()
            .map(|[x, y, theta]| Pose2 { x, y, theta })
            .collect();
        self.read(py, |grid| {
            grid.match_many(&pairs, &guesses, &options, phases.as_deref(), threads)
        })?
        .map(|results| results.into_iter().map(PyMatchResult::from).collect())
        .map_err(to_py)
    }

    #[doc = stub_doc!("NdtGrid.evaluate")]
    #[pyo3(signature = (
        points, pose, *, expansion = 10.0, sigma_floor = 0.02, shape_cell = 0.32, neighbor_search = true, fuse_minority = true,
        pair_neighbors = false, search_radius = 1
    ))]
    #[allow(clippy::too_many_arguments)]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        pose: &Bound<'py, PyAny>,
        expansion: f64,
        sigma_floor: f64,
        shape_cell: f64,
        neighbor_search: bool,
        fuse_minority: bool,
        pair_neighbors: bool,
        search_radius: i64,
    ) -> PyResult<Terms<'py>> {
        let defaults = MatchOptions::default();
        let options = MatchOptions {
            expansion,
            sigma_floor,
            shape_cell,
            neighbor_search,
            fuse_minority,
            pair_neighbors,
            search_radius: count("search_radius", search_radius)?,
            ..defaults
        };
        let pts = points_arg(points)?;
        let pairs = pts.as_pairs()?;
        let p = crate::convert::pose(pose, "pose")?;
        let at = Pose2 {
            x: p[0],
            y: p[1],
            theta: p[2],
        };
        let t = self
            .read(py, |grid| grid.score_terms(pairs, at, &options))?
            .map_err(to_py)?;
        Ok((
            t.score,
            vec3(py, [t.gradient.x, t.gradient.y, t.gradient.z]),
            mat3(py, rows(&t.hessian))?,
            t.matched,
        ))
    }

    #[doc = stub_doc!("NdtGrid.cells")]
    fn cells<'py>(&self, py: Python<'py>) -> PyResult<Cells<'py>> {
        let (centres, counts) = self.read(py, |g| {
            let s = g.cell_size();
            let recs = g.cells();
            let mut centres = Vec::with_capacity(recs.len() * 2);
            let mut counts = Vec::with_capacity(recs.len());
            for r in &recs {
                let c = r.key.center(s);
                centres.extend_from_slice(&[c.x, c.y]);
                counts.push(i64::try_from(r.count).unwrap_or(i64::MAX));
            }
            (centres, counts)
        })?;
        let k = counts.len();
        Ok((
            PyArray1::from_vec(py, centres).reshape([k, 2])?,
            PyArray1::from_vec(py, counts),
        ))
    }

    #[doc = stub_doc!("NdtGrid.cell_statistics")]
    fn cell_statistics<'py>(&self, py: Python<'py>) -> PyResult<crate::state::StateArrays<'py>> {
        let flat = self.read(py, |g| {
            let recs = g.cells();
            crate::state::flatten_rows(recs.iter().map(|r| (r.key, r.count, &r.sum, &r.scatter)))
        })?;
        crate::state::to_arrays(py, flat)
    }

    #[doc = stub_doc!("NdtGrid.cell_states")]
    fn cell_states<'py>(&self, py: Python<'py>) -> PyResult<crate::state::StateArrays<'py>> {
        let v = self.read(py, crate::state::flatten)?;
        crate::state::to_arrays(py, v)
    }

    #[doc = stub_doc!("NdtGrid.from_cell_states")]
    #[staticmethod]
    fn from_cell_states(
        cell_size: f64,
        indices: &Bound<'_, PyAny>,
        counts: &Bound<'_, PyAny>,
        sums: &Bound<'_, PyAny>,
        scatters: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        crate::state::from_arrays(cell_size, indices, counts, sums, scatters).map(Self::from)
    }

    #[doc = stub_doc!("NdtGrid.to_bytes")]
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = self.read(py, NdtGrid::to_bytes)?.map_err(to_py)?;
        Ok(PyBytes::new(py, &bytes))
    }

    #[doc = stub_doc!("NdtGrid.from_bytes")]
    #[classmethod]
    fn from_bytes(_cls: &Bound<'_, PyType>, py: Python<'_>, data: &[u8]) -> PyResult<Self> {
        py.detach(|| NdtGrid::from_bytes(data))
            .map(Self::from)
            .map_err(to_py)
    }

    #[doc = stub_doc!("NdtGrid.save")]
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let bytes = self.read(py, NdtGrid::to_bytes)?.map_err(to_py)?;
        py.detach(|| ndt_core::persist::write_atomic(&path, &bytes))
            .map_err(to_py)
    }

    #[doc = stub_doc!("NdtGrid.load")]
    #[classmethod]
    fn load(_cls: &Bound<'_, PyType>, py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        py.detach(|| NdtGrid::load(&path))
            .map(Self::from)
            .map_err(to_py)
    }

    /// Pickle (and `copy`) through the file format's bytes.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Reduced<'py>> {
        let from_bytes = py.get_type::<Self>().getattr("from_bytes")?;
        Ok((from_bytes, (self.to_bytes(py)?,)))
    }
}

/// What `__reduce__` returns: a constructor from bytes and the bytes.
pub(crate) type Reduced<'py> = (Bound<'py, PyAny>, (Bound<'py, PyBytes>,));

fn points_arg<'py>(obj: &Bound<'py, PyAny>) -> PyResult<crate::convert::Points<'py>> {
    points(obj, "points")
}
