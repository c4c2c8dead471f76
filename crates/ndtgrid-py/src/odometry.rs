//! `ndtgrid._core.OdometryLoop`: the core's scan-to-map odometry loop, and
//! `OdometryStep`, the record of one step. The Python class
//! `ndtgrid.Odometry` wraps them with a dataclass config.

use std::sync::Mutex;

use ndt_core::{MatchOptions, Odometry, OdometryConfig, Pose2, StepOutcome};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};

use crate::convert::{count, level_mask, level_tuple, pose, vec3, vector};
use crate::errors::{poisoned, to_py};
use crate::grid::PyNdtGrid;
use crate::record::reduce;

#[doc = stub_doc!("OdometryLoop")]
#[pyclass(name = "OdometryLoop", module = "ndtgrid._core", frozen)]
pub struct PyOdometry {
    inner: Mutex<Odometry>,
}

record! {
    #[doc = stub_doc!("OdometryStep")]
    #[pyclass(name = "OdometryStep", module = "ndtgrid._core", frozen)]
    pub struct PyStep(StepState) {
        pose: [f64; 3],
        prediction: [f64; 3],
        #[pyo3(get)]
        matched: bool,
        #[pyo3(get)]
        accepted: bool,
        #[pyo3(get)]
        multi_start: bool,
        #[pyo3(get)]
        inserted: bool,
        #[pyo3(get)]
        converged: bool,
        #[pyo3(get)]
        iterations: u32,
        #[pyo3(get)]
        num_matched: usize,
        #[pyo3(get)]
        num_points: usize,
    }
}

impl From<StepOutcome> for PyStep {
    fn from(s: StepOutcome) -> Self {
        Self {
            pose: s.pose.to_array(),
            prediction: s.prediction.to_array(),
            matched: s.matched.is_some(),
            accepted: s.accepted,
            multi_start: s.multi_start,
            inserted: s.inserted,
            converged: s.matched.as_ref().is_some_and(|m| m.converged),
            iterations: s.matched.as_ref().map_or(0, |m| m.iterations),
            num_matched: s.matched.as_ref().map_or(0, |m| m.num_matched),
            num_points: s.num_points,
        }
    }
}

#[pymethods]
impl PyStep {
    /// `(3,)` pose of the scan.
    #[getter]
    fn pose<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec3(py, self.pose)
    }

    /// `(3,)` prediction of the motion prior.
    #[getter]
    fn prediction<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec3(py, self.prediction)
    }

    #[doc = stub_doc!("OdometryStep.__reduce__")]
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (StepState,))> {
        reduce(slf, slf.get().state())
    }

    /// The step `__reduce__` took apart.
    #[classmethod]
    fn _restore(_cls: &Bound<'_, PyType>, state: StepState) -> Self {
        Self::from_state(state)
    }

    fn __repr__(&self) -> String {
        let [x, y, t] = self.pose;
        let b = |v: bool| if v { "True" } else { "False" };
        format!(
            "OdometryStep(pose=[{x:.6}, {y:.6}, {t:.6}], accepted={}, multi_start={}, \
             inserted={}, converged={}, iterations={}, num_matched={}, num_points={})",
            b(self.accepted),
            b(self.multi_start),
            b(self.inserted),
            b(self.converged),
            self.iterations,
            self.num_matched,
            self.num_points
        )
    }
}

impl PyOdometry {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, Odometry>> {
        self.inner.lock().map_err(|_| poisoned())
    }

    /// Runs `f` on the loop with the GIL released: waiting for another
    /// thread's `step` must not stall every other Python thread.
    fn with<T: Send>(&self, py: Python<'_>, f: impl FnOnce(&Odometry) -> T + Send) -> PyResult<T> {
        py.detach(|| self.lock().map(|o| f(&o)))
    }
}

#[pymethods]
impl PyOdometry {
    #[new]
    #[pyo3(signature = (
        cell_size = 0.02, *, min_range = None, max_range = None, insert_distance = None,
        insert_angle = None, map_window = None, match_insert_distance = None,
        match_insert_angle = None, match_map_window = None, min_match_ratio = None,
        bootstrap_insertions = None,
        rotation_search = None,
        rotation_step = None, prior_gap_distance = None, prior_gap_angle = None,
        expansion = None, sigma_floor = None, shape_cell = None,
        neighbor_search = None, fuse_minority = None, search_radius = None,
        max_iterations = None, translation_tolerance = None, rotation_tolerance = None,
        max_step_cells = None, max_step_rotation = None,
        levels = None, skip_levels = None, coarse_rotation_search = None, coarse_rotation_gate = None,
        freeze_unconstrained = None, freeze_ratio = None, coarse_model = None,
        outlier_filter = None, edge_removal = None, backshift_rejection = None,
        observation_check = None, radial_confirmation = None, match_filtered_map = None,
        background_mapper = None, build_map = None
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        cell_size: f64,
        min_range: Option<f64>,
        max_range: Option<f64>,
        insert_distance: Option<f64>,
        insert_angle: Option<f64>,
        map_window: Option<i64>,
        match_insert_distance: Option<f64>,
        match_insert_angle: Option<f64>,
        match_map_window: Option<i64>,
        min_match_ratio: Option<f64>,
        bootstrap_insertions: Option<i64>,
        rotation_search: Option<f64>,
        rotation_step: Option<f64>,
        prior_gap_distance: Option<f64>,
        prior_gap_angle: Option<f64>,
        expansion: Option<f64>,
        sigma_floor: Option<f64>,
        shape_cell: Option<f64>,
        neighbor_search: Option<bool>,
        fuse_minority: Option<bool>,
        search_radius: Option<i64>,
        max_iterations: Option<i64>,
        translation_tolerance: Option<f64>,
        rotation_tolerance: Option<f64>,
        max_step_cells: Option<f64>,
        max_step_rotation: Option<f64>,
        levels: Option<i64>,
        skip_levels: Option<Vec<i64>>,
        coarse_rotation_search: Option<f64>,
        coarse_rotation_gate: Option<f64>,
        freeze_unconstrained: Option<bool>,
        freeze_ratio: Option<f64>,
        coarse_model: Option<bool>,
        outlier_filter: Option<bool>,
        edge_removal: Option<bool>,
        backshift_rejection: Option<bool>,
        observation_check: Option<bool>,
        radial_confirmation: Option<bool>,
        match_filtered_map: Option<bool>,
        background_mapper: Option<bool>,
        build_map: Option<bool>,
    ) -> PyResult<Self> {
        let d = OdometryConfig::default();
        let m = d.matcher;
        let window = map_window
            .map(|w| count("map_window", w))
            .transpose()?
            .map_or(d.map_window, |w| w as usize);
        let match_window = match_map_window
            .map(|w| count("match_map_window", w))
            .transpose()?
            .map_or(d.match_map_window, |w| w as usize);
        let matcher = MatchOptions {
            expansion: expansion.unwrap_or(m.expansion),
            sigma_floor: sigma_floor.unwrap_or(m.sigma_floor),
            shape_cell: shape_cell.unwrap_or(m.shape_cell),
            neighbor_search: neighbor_search.unwrap_or(m.neighbor_search),
            fuse_minority: fuse_minority.unwrap_or(m.fuse_minority),
            search_radius: search_radius
                .map(|r| count("search_radius", r))
                .transpose()?
                .unwrap_or(m.search_radius),
            max_iterations: max_iterations
                .map(|r| count("max_iterations", r))
                .transpose()?
                .unwrap_or(m.max_iterations),
            translation_tolerance: translation_tolerance.unwrap_or(m.translation_tolerance),
            rotation_tolerance: rotation_tolerance.unwrap_or(m.rotation_tolerance),
            max_step_cells: max_step_cells.unwrap_or(m.max_step_cells),
            max_step_rotation: max_step_rotation.unwrap_or(m.max_step_rotation),
            levels: match levels {
                Some(l) => Some(count("levels", l)?),
                None => m.levels,
            },
            skip_levels: level_mask("skip_levels", skip_levels.as_deref(), m.skip_levels)?,
            rotation_search: coarse_rotation_search.unwrap_or(m.rotation_search),
            freeze_unconstrained: freeze_unconstrained.unwrap_or(m.freeze_unconstrained),
            freeze_ratio: freeze_ratio.unwrap_or(m.freeze_ratio),
            coarse_model: coarse_model.unwrap_or(m.coarse_model),
            ..m
        };
        let config = OdometryConfig {
            cell_size,
            min_range: min_range.unwrap_or(d.min_range),
            max_range: max_range.unwrap_or(d.max_range),
            insert_distance: insert_distance.unwrap_or(d.insert_distance),
            insert_angle: insert_angle.unwrap_or(d.insert_angle),
            match_insert_distance: match_insert_distance.unwrap_or(d.match_insert_distance),
            match_insert_angle: match_insert_angle.unwrap_or(d.match_insert_angle),
            match_map_window: match_window,
            map_window: window,
            min_match_ratio: min_match_ratio.unwrap_or(d.min_match_ratio),
            bootstrap_insertions: bootstrap_insertions
                .map(|b| count("bootstrap_insertions", b))
                .transpose()?
                .map_or(d.bootstrap_insertions, |b| b as usize),
            rotation_search: rotation_search.unwrap_or(d.rotation_search),
            rotation_step: rotation_step.unwrap_or(d.rotation_step),
            prior_gap_distance: prior_gap_distance.unwrap_or(d.prior_gap_distance),
            prior_gap_angle: prior_gap_angle.unwrap_or(d.prior_gap_angle),
            coarse_rotation_gate: coarse_rotation_gate.unwrap_or(d.coarse_rotation_gate),
            matcher,
            mapper: ndt_core::MapperOptions {
                outlier_filter: outlier_filter.unwrap_or(d.mapper.outlier_filter),
                edge_removal: edge_removal.unwrap_or(d.mapper.edge_removal),
                backshift_rejection: backshift_rejection.unwrap_or(d.mapper.backshift_rejection),
                observation_check: observation_check.unwrap_or(d.mapper.observation_check),
                radial_confirmation: radial_confirmation.unwrap_or(d.mapper.radial_confirmation),
                ..d.mapper
            },
            match_filtered_map: match_filtered_map.unwrap_or(d.match_filtered_map),
            background_mapper: background_mapper.unwrap_or(d.background_mapper),
            build_map: build_map.unwrap_or(d.build_map),
        };
        Ok(Self {
            inner: Mutex::new(Odometry::new(config).map_err(to_py)?),
        })
    }

    #[doc = stub_doc!("OdometryLoop.step")]
    #[pyo3(signature = (ranges, angles, odom = None))]
    fn step(
        &self,
        py: Python<'_>,
        ranges: &Bound<'_, PyAny>,
        angles: &Bound<'_, PyAny>,
        odom: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyStep> {
        let r = vector(ranges, "ranges")?;
        let a = vector(angles, "angles")?;
        let (r, a) = (r.as_slice()?, a.as_slice()?);
        let o = odom.map(|o| pose(o, "odom")).transpose()?.map(|p| Pose2 {
            x: p[0],
            y: p[1],
            theta: p[2],
        });
        py.detach(|| {
            let mut odo = self.lock()?;
            odo.step(r, a, o).map_err(to_py)
        })
        .map(PyStep::from)
    }

    #[doc = stub_doc!("OdometryLoop.poses")]
    #[getter]
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let flat: Vec<f64> = self.with(py, |o| {
            o.poses().iter().flat_map(|p| p.to_array()).collect()
        })?;
        let t = flat.len() / 3;
        PyArray1::from_vec(py, flat).reshape([t, 3])
    }

    #[doc = stub_doc!("OdometryLoop.insertions")]
    #[getter]
    fn insertions(&self, py: Python<'_>) -> PyResult<u64> {
        self.with(py, Odometry::insertions)
    }

    #[doc = stub_doc!("OdometryLoop.grid_insertions")]
    #[getter]
    fn grid_insertions(&self, py: Python<'_>) -> PyResult<u64> {
        self.with(py, Odometry::grid_insertions)
    }

    /// Cells in the map now.
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.with(py, |o| o.grid().len())
    }

    #[doc = stub_doc!("OdometryLoop.grid")]
    fn grid(&self, py: Python<'_>) -> PyResult<PyNdtGrid> {
        let grid = self.with(py, |o| o.grid().clone())?;
        Ok(PyNdtGrid::from(grid))
    }

    #[doc = stub_doc!("OdometryLoop.wait_for_mapper")]
    fn wait_for_mapper(&self, py: Python<'_>) -> PyResult<()> {
        self.with(py, Odometry::wait_for_mapper)
    }

    #[doc = stub_doc!("OdometryLoop.mapper")]
    fn mapper(&self, py: Python<'_>) -> PyResult<crate::mapper::PyMapper> {
        let mapper = self
            .with(py, |o| o.mapper().map(|m| ndt_core::Mapper::clone(&m)))?
            .map_err(to_py)?;
        crate::mapper::PyMapper::from_core(py, mapper)
    }

    #[doc = stub_doc!("OdometryLoop.config")]
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = self.with(py, |o| *o.config())?;
        config_dict(py, &c)
    }
}

fn config_dict<'py>(py: Python<'py>, c: &OdometryConfig) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("cell_size", c.cell_size)?;
    out.set_item("min_range", c.min_range)?;
    out.set_item("max_range", c.max_range)?;
    out.set_item("insert_distance", c.insert_distance)?;
    out.set_item("insert_angle", c.insert_angle)?;
    out.set_item("map_window", c.map_window)?;
    out.set_item("match_insert_distance", c.match_insert_distance)?;
    out.set_item("match_insert_angle", c.match_insert_angle)?;
    out.set_item("match_map_window", c.match_map_window)?;
    out.set_item("min_match_ratio", c.min_match_ratio)?;
    out.set_item("bootstrap_insertions", c.bootstrap_insertions)?;
    out.set_item("rotation_search", c.rotation_search)?;
    out.set_item("rotation_step", c.rotation_step)?;
    out.set_item("prior_gap_distance", c.prior_gap_distance)?;
    out.set_item("prior_gap_angle", c.prior_gap_angle)?;
    out.set_item("expansion", c.matcher.expansion)?;
    out.set_item("sigma_floor", c.matcher.sigma_floor)?;
    out.set_item("shape_cell", c.matcher.shape_cell)?;
    out.set_item("neighbor_search", c.matcher.neighbor_search)?;
    out.set_item("fuse_minority", c.matcher.fuse_minority)?;
    out.set_item("search_radius", c.matcher.search_radius)?;
    out.set_item("max_iterations", c.matcher.max_iterations)?;
    out.set_item("translation_tolerance", c.matcher.translation_tolerance)?;
    out.set_item("rotation_tolerance", c.matcher.rotation_tolerance)?;
    out.set_item("max_step_cells", c.matcher.max_step_cells)?;
    out.set_item("max_step_rotation", c.matcher.max_step_rotation)?;
    out.set_item("levels", c.matcher.levels)?;
    out.set_item("skip_levels", level_tuple(py, c.matcher.skip_levels)?)?;
    out.set_item("coarse_rotation_search", c.matcher.rotation_search)?;
    out.set_item("coarse_rotation_gate", c.coarse_rotation_gate)?;
    out.set_item("freeze_unconstrained", c.matcher.freeze_unconstrained)?;
    out.set_item("freeze_ratio", c.matcher.freeze_ratio)?;
    out.set_item("coarse_model", c.matcher.coarse_model)?;
    out.set_item("outlier_filter", c.mapper.outlier_filter)?;
    out.set_item("edge_removal", c.mapper.edge_removal)?;
    out.set_item("backshift_rejection", c.mapper.backshift_rejection)?;
    out.set_item("observation_check", c.mapper.observation_check)?;
    out.set_item("radial_confirmation", c.mapper.radial_confirmation)?;
    out.set_item("match_filtered_map", c.match_filtered_map)?;
    out.set_item("background_mapper", c.background_mapper)?;
    out.set_item("build_map", c.build_map)?;
    Ok(out)
}

#[doc = stub_doc!("default_odometry_config")]
#[pyfunction]
pub fn default_odometry_config(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    config_dict(py, &OdometryConfig::default())
}
