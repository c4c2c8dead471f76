//! The build of the core's multiversioned kernels that runs on this
//! processor ([`ndt_core::kernels`]), for benchmark reports.

use pyo3::prelude::*;

/// `"AVX-512"`, `"AVX2"` or `"NEON"`: the vector extension of the core's
/// kernels here; `None` for their generic build.
#[pyfunction]
pub fn vector_extension() -> Option<&'static str> {
    ndt_core::kernels::vector_extension().map(|v| v.name())
}
