//! The build of the core's multiversioned kernels that runs on this
//! processor ([`ndt_core::kernels`]), for benchmark reports.

use pyo3::prelude::*;

#[doc = stub_doc!("vector_extension")]
#[pyfunction]
pub fn vector_extension() -> Option<&'static str> {
    ndt_core::kernels::vector_extension().map(|v| v.name())
}
