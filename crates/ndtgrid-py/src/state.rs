//! A grid's exact cell state as numpy arrays and back (the conversion only;
//! the core validates the cells).

use ndt_core::nalgebra::{Matrix2, Vector2};
use ndt_core::{CellKey, CellStats, NdtGrid};
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::errors::to_py;

/// `(indices (K, 2) int64, counts (K,) int64, sums (K, 2), scatters (K, 2, 2))`.
pub type StateArrays<'py> = (
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray3<f64>>,
);

/// Flat copies of the cell states: keys, counts, sums, scatters (row-major).
pub type StateVecs = (Vec<i64>, Vec<i64>, Vec<f64>, Vec<f64>);

/// Flattens `(key, count, sum, scatter)` rows, in the order given.
pub fn flatten_rows<'a>(
    rows: impl ExactSizeIterator<Item = (CellKey, u64, &'a Vector2<f64>, &'a Matrix2<f64>)>,
) -> StateVecs {
    let k = rows.len();
    let (mut keys, mut counts) = (Vec::with_capacity(2 * k), Vec::with_capacity(k));
    let (mut sums, mut scatters) = (Vec::with_capacity(2 * k), Vec::with_capacity(4 * k));
    for (key, count, sum, m) in rows {
        keys.extend_from_slice(&[i64::from(key.ix), i64::from(key.iy)]);
        counts.push(i64::try_from(count).unwrap_or(i64::MAX));
        sums.extend_from_slice(&[sum.x, sum.y]);
        scatters.extend_from_slice(&[m[(0, 0)], m[(0, 1)], m[(1, 0)], m[(1, 1)]]);
    }
    (keys, counts, sums, scatters)
}

/// Flattens the grid's cell states (sums about each cell's centre).
pub fn flatten(grid: &NdtGrid) -> StateVecs {
    let states = grid.cell_states();
    flatten_rows(
        states
            .iter()
            .map(|(k, s)| (*k, s.count, &s.sum, &s.scatter)),
    )
}

/// The flattened states as numpy arrays.
pub fn to_arrays(py: Python<'_>, v: StateVecs) -> PyResult<StateArrays<'_>> {
    let (keys, counts, sums, scatters) = v;
    let k = counts.len();
    Ok((
        PyArray1::from_vec(py, keys).reshape([k, 2])?,
        PyArray1::from_vec(py, counts),
        PyArray1::from_vec(py, sums).reshape([k, 2])?,
        PyArray1::from_vec(py, scatters).reshape([k, 2, 2])?,
    ))
}

/// `numpy.ascontiguousarray(obj, dtype)` with the expected shape checked
/// (`None` in `shape` matches any length).
fn array<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
    dtype: &str,
    shape: &[Option<usize>],
) -> PyResult<Bound<'py, PyAny>> {
    let np = obj.py().import("numpy")?;
    let arr = np
        .call_method1("ascontiguousarray", (obj, np.getattr(dtype)?))
        .map_err(|e| PyValueError::new_err(format!("{what}: expected {dtype} numbers: {e}")))?;
    let untyped = arr.cast::<numpy::PyUntypedArray>()?;
    let got = untyped.shape();
    let ok = got.len() == shape.len()
        && got
            .iter()
            .zip(shape)
            .all(|(g, s)| s.is_none_or(|s| s == *g));
    if !ok {
        let want: Vec<String> = shape
            .iter()
            .map(|s| s.map_or_else(|| "K".to_string(), |v| v.to_string()))
            .collect();
        return Err(PyValueError::new_err(format!(
            "{what}: expected shape ({}), got {got:?}",
            want.join(", ")
        )));
    }
    Ok(arr)
}

fn slice_of<T: numpy::Element + Copy>(arr: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<T>> {
    let a = arr.cast::<numpy::PyArrayDyn<T>>()?.readonly();
    a.as_slice()
        .map(<[T]>::to_vec)
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))
}

/// Rebuilds a grid from the arrays of [`to_arrays`].
pub fn from_arrays(
    cell_size: f64,
    indices: &Bound<'_, PyAny>,
    counts: &Bound<'_, PyAny>,
    sums: &Bound<'_, PyAny>,
    scatters: &Bound<'_, PyAny>,
) -> PyResult<NdtGrid> {
    let counts = array(counts, "counts", "int64", &[None])?;
    let k = counts.cast::<numpy::PyUntypedArray>()?.shape()[0];
    let indices = array(indices, "indices", "int64", &[Some(k), Some(2)])?;
    let sums = array(sums, "sums", "float64", &[Some(k), Some(2)])?;
    let scatters = array(
        scatters,
        "scatters",
        "float64",
        &[Some(k), Some(2), Some(2)],
    )?;
    let (ix, n) = (
        slice_of::<i64>(&indices, "indices")?,
        slice_of::<i64>(&counts, "counts")?,
    );
    let (m, s) = (
        slice_of::<f64>(&sums, "sums")?,
        slice_of::<f64>(&scatters, "scatters")?,
    );
    let mut states = Vec::with_capacity(k);
    for i in 0..k {
        let coord = |v: i64| {
            i32::try_from(v).map_err(|_| {
                PyValueError::new_err(format!("indices: cell {i} has an index beyond +-2**30"))
            })
        };
        let count = u64::try_from(n[i]).map_err(|_| {
            PyValueError::new_err(format!("counts: cell {i} has a negative count {}", n[i]))
        })?;
        let key = CellKey {
            ix: coord(ix[2 * i])?,
            iy: coord(ix[2 * i + 1])?,
        };
        let stats = CellStats {
            count,
            sum: Vector2::new(m[2 * i], m[2 * i + 1]),
            scatter: Matrix2::new(s[4 * i], s[4 * i + 1], s[4 * i + 2], s[4 * i + 3]),
        };
        states.push((key, stats));
    }
    NdtGrid::from_cell_states(cell_size, &states).map_err(to_py)
}
