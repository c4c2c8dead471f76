//! numpy ⇄ core conversion and argument validation (shapes and dtypes; the
//! core checks values). Arrays that are already C-contiguous float64 are
//! borrowed, never copied.

use ndt_core::nalgebra::Matrix3;
use numpy::{
    PyArray1, PyArray2, PyArrayDescrMethods, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyAnyMethods, PyTuple};

/// `(N, 2)` float64 points, borrowed from a C-contiguous numpy array.
pub struct Points<'py> {
    array: PyReadonlyArray2<'py, f64>,
}

impl Points<'_> {
    /// The points as `[x, y]` pairs \[m\].
    pub fn as_pairs(&self) -> PyResult<&[[f64; 2]]> {
        let flat = self
            .array
            .as_slice()
            .map_err(|e| PyValueError::new_err(format!("points: {e}")))?;
        bytemuck::try_cast_slice(flat)
            .map_err(|e| PyValueError::new_err(format!("points: cannot view as (N, 2): {e}")))
    }

    /// Each of `sets` as `[x, y]` pairs ([`Points::as_pairs`]).
    pub fn all_pairs<'a>(sets: &'a [Points<'_>]) -> PyResult<Vec<&'a [[f64; 2]]>> {
        sets.iter().map(Points::as_pairs).collect()
    }
}

fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The name of `obj`'s type, for messages (empty if it has none).
fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_default()
}

/// `numpy.asarray(obj)` with a `TypeError` naming `what` when `obj` is not
/// array-like, and with the dtype checked to be real numbers.
fn real_array<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyUntypedArray>> {
    let py = obj.py();
    // An ndarray itself (not a subclass) is what `numpy.asarray` returns for
    // it: the common case skips the call (and `asarray` is looked up once).
    static ASARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    let given = obj.get_type().is(py.get_type::<PyUntypedArray>());
    let arr = if given {
        Ok(obj.clone())
    } else {
        ASARRAY
            .import(py, "numpy", "asarray")
            .and_then(|asarray| asarray.call1((obj,)))
    };
    let not_array_like = || {
        PyTypeError::new_err(format!(
            "{what}: expected an array-like of real numbers, got {}",
            type_name(obj)
        ))
    };
    let arr = arr.map_err(|_| not_array_like())?;
    let arr = arr.cast_into::<PyUntypedArray>().map_err(|_| {
        PyTypeError::new_err(format!("{what}: expected an array-like of real numbers"))
    })?;
    let dtype = arr.dtype();
    // NumPy before 1.24 makes ragged nested lists an object array where later
    // versions refuse them: the same error either way.
    if !given && dtype.kind() == b'O' {
        return Err(not_array_like());
    }
    if !matches!(dtype.kind(), b'f' | b'i' | b'u') {
        return Err(PyTypeError::new_err(format!(
            "{what}: expected real numbers (float64), got dtype {}",
            dtype.str().map(|s| s.to_string()).unwrap_or_default()
        )));
    }
    Ok(arr)
}

/// A C-contiguous float64 copy of `arr` unless it already is one.
fn as_f64_contiguous<'py>(arr: Bound<'py, PyUntypedArray>) -> PyResult<Bound<'py, PyAny>> {
    let is_f64 = arr.dtype().is_equiv_to(&numpy::dtype::<f64>(arr.py()));
    if is_f64 && arr.is_c_contiguous() {
        return Ok(arr.into_any());
    }
    static CONTIGUOUS: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    let py = arr.py();
    CONTIGUOUS
        .import(py, "numpy", "ascontiguousarray")?
        .call1((arr, numpy::dtype::<f64>(py)))
}

/// `arr` (named `what`) as a C-contiguous float64 array of `cols` columns,
/// copied only when it is not one; `shape` is the shape the error names.
fn rows_of<'py>(
    arr: Bound<'py, PyUntypedArray>,
    what: &str,
    cols: usize,
    shape: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let got = arr.shape();
    if got.len() != 2 || got[1] != cols {
        return Err(PyValueError::new_err(format!(
            "{what}: expected an array of shape {shape}, got shape {}",
            shape_text(got)
        )));
    }
    as_f64_contiguous(arr)?
        .cast_into::<PyArray2<f64>>()
        .map_err(|e| PyTypeError::new_err(format!("{what}: {e}")))
}

/// Validates and borrows `(N, 2)` points named `what`.
pub fn points<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Points<'py>> {
    let array = rows_of(real_array(obj, what)?, what, 2, "(N, 2)")?.readonly();
    Ok(Points { array })
}

/// Validates and borrows a sequence named `what` of `(N, 2)` points (a list
/// of arrays, or one array of shape `(K, N, 2)`); item `i` is named `scan i:
/// points` in errors, and one `(N, 2)` array is pointed to the method `one`
/// that takes a single scan.
pub fn point_sets<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
    one: &str,
) -> PyResult<Vec<Points<'py>>> {
    if let Ok(array) = obj.cast::<PyUntypedArray>() {
        if array.ndim() < 3 {
            return Err(PyTypeError::new_err(format!(
                "{what}: expected a sequence of (N, 2) arrays, got one array of shape {} \
                 (one scan: use {one})",
                shape_text(array.shape())
            )));
        }
    }
    let items = obj.try_iter().map_err(|_| {
        PyTypeError::new_err(format!(
            "{what}: expected a sequence of (N, 2) arrays, got {}",
            type_name(obj)
        ))
    })?;
    items
        .enumerate()
        .map(|(i, item)| points(&item?, &format!("scan {i}: points")))
        .collect()
}

/// A 1-D float64 array, borrowed from a C-contiguous numpy array.
pub struct Vector<'py> {
    array: PyReadonlyArray1<'py, f64>,
}

impl Vector<'_> {
    /// The values.
    pub fn as_slice(&self) -> PyResult<&[f64]> {
        self.array
            .as_slice()
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }
}

/// Validates and borrows a 1-D array named `what`.
pub fn vector<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Vector<'py>> {
    let arr = real_array(obj, what)?;
    let shape = arr.shape();
    if shape.len() != 1 {
        return Err(PyValueError::new_err(format!(
            "{what}: expected a 1-D array, got shape {}",
            shape_text(shape)
        )));
    }
    let array = as_f64_contiguous(arr)?
        .cast_into::<PyArray1<f64>>()
        .map_err(|e| PyTypeError::new_err(format!("{what}: {e}")))?
        .readonly();
    Ok(Vector { array })
}

/// Validates a `[x, y, theta]` pose named `what`.
pub fn pose(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<[f64; 3]> {
    let arr = real_array(obj, what)?;
    if arr.shape() != [3] {
        return Err(PyValueError::new_err(format!(
            "{what}: expected 3 values [x, y, theta], got shape {}",
            shape_text(arr.shape())
        )));
    }
    let arr = as_f64_contiguous(arr)?
        .cast_into::<PyArray1<f64>>()
        .map_err(|e| PyTypeError::new_err(format!("{what}: {e}")))?;
    // Read while the GIL is held, so no borrow of the array to track (the
    // numpy crate's borrow bookkeeping is a global table's insert and
    // removal per borrow).
    match [0, 1, 2].map(|i| arr.get_owned([i])) {
        [Some(x), Some(y), Some(theta)] => Ok([x, y, theta]),
        _ => Err(PyValueError::new_err(format!(
            "{what}: expected 3 values [x, y, theta]"
        ))),
    }
}

/// Validates and copies `(K, 3)` poses `[x, y, theta]` named `what` (an
/// empty sequence is no pose).
pub fn poses(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; 3]>> {
    let arr = real_array(obj, what)?;
    if arr.shape() == [0] {
        return Ok(Vec::new());
    }
    let arr = rows_of(arr, what, 3, "(K, 3), one [x, y, theta] per row")?;
    // Copied while the GIL is held: no borrow of the array to track.
    let flat = arr
        .to_vec()
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    Ok(flat.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect())
}

/// A `(3,)` float64 array.
pub fn vec3<'py>(py: Python<'py>, v: [f64; 3]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, &v)
}

/// Row-major copy of a 3×3 matrix.
pub fn rows(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ]
}

/// A `(3, 3)` float64 array from a row-major matrix.
pub fn mat3<'py>(py: Python<'py>, m: [[f64; 3]; 3]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    PyArray1::from_slice(py, m.as_flattened()).reshape([3, 3])
}

/// Pyramid levels named by number (option `what`, e.g. `skip_levels`) as a
/// mask, bit `l` for level `l`: each between 1 and the pyramid's last;
/// `default` when not given (`None`).
pub fn level_mask(what: &str, levels: Option<&[i64]>, default: u32) -> PyResult<u32> {
    let Some(levels) = levels else {
        return Ok(default);
    };
    let last = ndt_core::pyramid::MAX_LEVELS as i64 - 1;
    levels.iter().try_fold(0u32, |mask, &l| {
        if (1..=last).contains(&l) {
            Ok(mask | 1 << l)
        } else {
            Err(PyValueError::new_err(format!(
                "{what}: expected pyramid levels between 1 and {last}, got {l}"
            )))
        }
    })
}

/// A mask of [`level_mask`] as `match`'s `skip_levels`: a tuple of the
/// levels in increasing order (empty for none: `None` asks for the default).
pub fn level_tuple(py: Python<'_>, mask: u32) -> PyResult<Bound<'_, PyTuple>> {
    let levels: Vec<u32> = (0..32).filter(|l| mask >> l & 1 == 1).collect();
    PyTuple::new(py, levels)
}

/// A non-negative integer option named `what`.
pub fn count(what: &str, value: i64) -> PyResult<u32> {
    u32::try_from(value).map_err(|_| {
        PyValueError::new_err(format!(
            "{what}: expected a non-negative integer below 2**32, got {value}"
        ))
    })
}
