//! `NdtGrid.match`'s keyword arguments ⇄ the core's `MatchOptions`: the
//! defaults and presets as keyword dictionaries, and the keyword arguments
//! `NdtGrid.match_many` passes on as options.

use ndt_core::MatchOptions;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{count, level_mask, level_tuple};

#[doc = stub_doc!("default_match_options")]
#[pyfunction]
pub fn default_match_options(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    options_dict(py, &MatchOptions::default())
}

#[doc = stub_doc!("preset_match_options")]
#[pyfunction]
pub fn preset_match_options<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyDict>> {
    match name {
        "paper" => options_dict(py, &MatchOptions::paper()),
        "original_ndt" => options_dict(py, &MatchOptions::original_ndt()),
        _ => Err(PyValueError::new_err(format!(
            "name: expected 'paper' or 'original_ndt', got {name:?}"
        ))),
    }
}

/// `MatchOptions` as `match` keyword arguments.
fn options_dict<'py>(py: Python<'py>, d: &MatchOptions) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("expansion", d.expansion)?;
    out.set_item("sigma_floor", d.sigma_floor)?;
    out.set_item("shape_cell", d.shape_cell)?;
    out.set_item("neighbor_search", d.neighbor_search)?;
    out.set_item("fuse_minority", d.fuse_minority)?;
    out.set_item("pair_neighbors", d.pair_neighbors)?;
    out.set_item("search_radius", d.search_radius)?;
    out.set_item("max_iterations", d.max_iterations)?;
    out.set_item("translation_tolerance", d.translation_tolerance)?;
    out.set_item("rotation_tolerance", d.rotation_tolerance)?;
    out.set_item("max_step_cells", d.max_step_cells)?;
    out.set_item("max_step_rotation", d.max_step_rotation)?;
    out.set_item("rotation_search", d.rotation_search)?;
    out.set_item("rotation_gate", d.rotation_gate)?;
    out.set_item("freeze_unconstrained", d.freeze_unconstrained)?;
    out.set_item("freeze_ratio", d.freeze_ratio)?;
    out.set_item("levels", d.levels)?;
    out.set_item("skip_levels", level_tuple(py, d.skip_levels)?)?;
    out.set_item("coarse_model", d.coarse_model)?;
    out.set_item("expansion_phases", py.None())?;
    out.set_item("parallel", d.parallel)?;
    Ok(out)
}

/// `match`'s keyword arguments in `kwargs` (the rest at their defaults, as
/// `match` has them) as core options and the phased expansions; a
/// `TypeError` naming `method` for a name `match` does not take.
pub fn options_from_kwargs(
    method: &str,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<(MatchOptions, Option<Vec<f64>>)> {
    let defaults = MatchOptions::default();
    let mut o = defaults;
    let mut phases = None;
    let Some(kwargs) = kwargs else {
        return Ok((o, phases));
    };
    for (key, value) in kwargs.iter() {
        let name: String = key.extract()?;
        let typed =
            |e: PyErr| PyTypeError::new_err(format!("argument '{name}': {}", e.value(key.py())));
        let real = || value.extract::<f64>().map_err(typed);
        let flag = || value.extract::<bool>().map_err(typed);
        let whole = || {
            value
                .extract::<i64>()
                .map_err(typed)
                .and_then(|v| count(&name, v))
        };
        match name.as_str() {
            "expansion" => o.expansion = real()?,
            "sigma_floor" => o.sigma_floor = real()?,
            "shape_cell" => o.shape_cell = real()?,
            "neighbor_search" => o.neighbor_search = flag()?,
            "fuse_minority" => o.fuse_minority = flag()?,
            "pair_neighbors" => o.pair_neighbors = flag()?,
            "search_radius" => o.search_radius = whole()?,
            "max_iterations" => o.max_iterations = whole()?,
            "translation_tolerance" => o.translation_tolerance = real()?,
            "rotation_tolerance" => o.rotation_tolerance = real()?,
            "max_step_cells" => o.max_step_cells = real()?,
            "max_step_rotation" => o.max_step_rotation = real()?,
            "rotation_search" => o.rotation_search = real()?,
            "rotation_gate" => o.rotation_gate = real()?,
            "freeze_unconstrained" => o.freeze_unconstrained = flag()?,
            "freeze_ratio" => o.freeze_ratio = real()?,
            "levels" => {
                let levels: Option<i64> = value.extract().map_err(typed)?;
                o.levels = levels.map(|l| count("levels", l)).transpose()?;
            }
            "skip_levels" => {
                let levels: Option<Vec<i64>> = value.extract().map_err(typed)?;
                o.skip_levels = level_mask("skip_levels", levels.as_deref(), defaults.skip_levels)?;
            }
            "coarse_model" => o.coarse_model = flag()?,
            "expansion_phases" => phases = value.extract().map_err(typed)?,
            "parallel" => o.parallel = flag()?,
            _ => {
                return Err(PyTypeError::new_err(format!(
                    "{method}() got an unexpected keyword argument '{name}'"
                )))
            }
        }
    }
    Ok((o, phases))
}
