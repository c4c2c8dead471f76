//! `ndtgrid.MapperOptions`: the frozen options of `ndtgrid.Mapper` (§V).

use ndt_core::MapperOptions;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};

use crate::convert::count;
use crate::errors::to_py;
use crate::record::reduce;

#[pymethods]
impl PyMapperOptions {
    #[new]
    #[pyo3(signature = (
        *, outlier_filter = true, edge_removal = true, area1_confirmation = true,
        backshift_rejection = true, observation_check = true, radial_confirmation = true,
        min_range = 0.0, max_range = f64::INFINITY, reliable_range = 0.5, cluster_gap = 0.05,
        cluster_spacing_factor = 2.0, small_object_size = 0.05, behind_com_margin = 0.0,
        backshift_window = 0.10, check_interval = 3, min_observations = 2, observation_support = true,
        clear_margin = 0.03, clear_margin_relative = 0.015, pass_radius = 0.005
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        outlier_filter: bool,
        edge_removal: bool,
        area1_confirmation: bool,
        backshift_rejection: bool,
        observation_check: bool,
        radial_confirmation: bool,
        min_range: f64,
        max_range: f64,
        reliable_range: f64,
        cluster_gap: f64,
        cluster_spacing_factor: f64,
        small_object_size: f64,
        behind_com_margin: f64,
        backshift_window: f64,
        check_interval: i64,
        min_observations: i64,
        observation_support: bool,
        clear_margin: f64,
        clear_margin_relative: f64,
        pass_radius: f64,
    ) -> PyResult<Self> {
        let options = MapperOptions {
            outlier_filter,
            edge_removal,
            area1_confirmation,
            backshift_rejection,
            observation_check,
            radial_confirmation,
            min_range,
            max_range,
            reliable_range,
            cluster_gap,
            cluster_spacing_factor,
            small_object_size,
            behind_com_margin,
            backshift_window,
            check_interval: count("check_interval", check_interval)?,
            min_observations: count("min_observations", min_observations)?,
            observation_support,
            clear_margin,
            clear_margin_relative,
            pass_radius,
        };
        options.validate().map_err(to_py)?;
        Ok(Self::from(options))
    }

    #[doc = stub_doc!("MapperOptions.as_dict")]
    fn as_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        options_dict(py, &self.core())
    }

    #[doc = stub_doc!("MapperOptions.replace")]
    #[pyo3(signature = (**changes))]
    fn replace<'py>(
        &self,
        py: Python<'py>,
        changes: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let all = options_dict(py, &self.core())?;
        if let Some(c) = changes {
            for (k, v) in c.iter() {
                if !all.contains(&k)? {
                    return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                        "MapperOptions.replace: unknown option {k}"
                    )));
                }
                all.set_item(k, v)?;
            }
        }
        py.get_type::<PyMapperOptions>().call((), Some(&all))
    }

    #[doc = stub_doc!("MapperOptions.__reduce__")]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyDict>,))> {
        reduce(slf, options_dict(slf.py(), &slf.get().core())?)
    }

    /// The options `__reduce__` took apart, checked as the constructor checks them.
    #[classmethod]
    fn _restore<'py>(
        cls: &Bound<'py, PyType>,
        options: &Bound<'py, PyDict>,
    ) -> PyResult<Bound<'py, PyAny>> {
        cls.call((), Some(options))
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let d = options_dict(py, &self.core())?;
        let mut parts = Vec::new();
        for (k, v) in d.iter() {
            parts.push(format!("{}={}", k, v.repr()?));
        }
        Ok(format!("MapperOptions({})", parts.join(", ")))
    }
}

/// Declares the Python class with one read-only attribute per core option,
/// its conversions, and `as_dict`'s content. Listing every field of the core
/// struct in the conversion makes a forgotten option a compile error.
macro_rules! options_class {
    ($($name:ident : $t:ty),* $(,)?) => {
        #[doc = stub_doc!("MapperOptions")]
        #[pyclass(name = "MapperOptions", module = "ndtgrid._core", frozen, eq)]
        #[derive(Clone, PartialEq)]
        pub struct PyMapperOptions {
            $( #[pyo3(get)] $name: $t, )*
        }

        impl From<MapperOptions> for PyMapperOptions {
            fn from(o: MapperOptions) -> Self {
                Self { $( $name: o.$name, )* }
            }
        }

        impl PyMapperOptions {
            /// The core's options.
            pub(crate) fn core(&self) -> MapperOptions {
                MapperOptions { $( $name: self.$name, )* }
            }
        }

        fn options_dict<'py>(py: Python<'py>, o: &MapperOptions) -> PyResult<Bound<'py, PyDict>> {
            let d = PyDict::new(py);
            $( d.set_item(stringify!($name), o.$name)?; )*
            Ok(d)
        }
    };
}

options_class!(
    outlier_filter: bool,
    edge_removal: bool,
    area1_confirmation: bool,
    backshift_rejection: bool,
    observation_check: bool,
    radial_confirmation: bool,
    min_range: f64,
    max_range: f64,
    reliable_range: f64,
    cluster_gap: f64,
    cluster_spacing_factor: f64,
    small_object_size: f64,
    behind_com_margin: f64,
    backshift_window: f64,
    check_interval: u32,
    min_observations: u32,
    observation_support: bool,
    clear_margin: f64,
    clear_margin_relative: f64,
    pass_radius: f64,
);

#[doc = stub_doc!("default_mapper_options")]
#[pyfunction]
pub fn default_mapper_options(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    options_dict(py, &MapperOptions::default())
}
