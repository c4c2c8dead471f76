//! The thin PyO3 layer of ndtgrid (`ndtgrid._core`): conversion, validation
//! and error mapping around `ndt-core`; no algorithm lives here.
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// The Python-facing items take the stubs' numpydoc docstrings (`stub_doc!`),
// which are not Markdown.
#![allow(clippy::doc_lazy_continuation)]

/// The Python docstring the type stubs give `$name` (`"Class"`,
/// `"Class.method"` or `"function"`), as the build script copied it: the
/// stubs are where the Python documentation is written (see `build.rs`).
macro_rules! stub_doc {
    ($name:literal) => {
        include_str!(concat!(env!("OUT_DIR"), "/doc/", $name, ".txt"))
    };
}

#[macro_use]
mod record;

mod convert;
mod errors;
mod freespace;
mod grid;
mod kernels;
mod mapper;
mod mapper_options;
mod match_options;
mod odometry;
mod ranges;
mod result;
mod se2;
mod small_object;
mod state;

use pyo3::prelude::*;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("FORMAT_VERSION", ndt_core::persist::VERSION)?;
    m.add_class::<grid::PyNdtGrid>()?;
    m.add_class::<result::PyMatchResult>()?;
    m.add_class::<mapper::PyMapper>()?;
    m.add_class::<mapper_options::PyMapperOptions>()?;
    m.add_class::<small_object::PySmallObject>()?;
    m.add_class::<small_object::PyRemovalCounts>()?;
    m.add_function(wrap_pyfunction!(mapper_options::default_mapper_options, m)?)?;
    m.add_class::<odometry::PyOdometry>()?;
    m.add_class::<odometry::PyStep>()?;
    m.add_class::<freespace::PyFreeSpace>()?;
    m.add_function(wrap_pyfunction!(odometry::default_odometry_config, m)?)?;
    m.add_function(wrap_pyfunction!(match_options::default_match_options, m)?)?;
    m.add_function(wrap_pyfunction!(match_options::preset_match_options, m)?)?;
    m.add_function(wrap_pyfunction!(ranges::ranges_to_points, m)?)?;
    m.add_function(wrap_pyfunction!(se2::compose, m)?)?;
    m.add_function(wrap_pyfunction!(se2::inverse, m)?)?;
    m.add_function(wrap_pyfunction!(se2::between, m)?)?;
    m.add_function(wrap_pyfunction!(kernels::vector_extension, m)?)?;
    Ok(())
}
