//! NumPy conversions: array-likes (arrays of any real dtype, lists) in, `float64` arrays out.

use crate::errors::invalid;
use nalgebra::{DMatrix, DVector};
use numpy::{AllowTypeChange, PyArray, PyArrayLike1, PyArrayLike2, PyArrayLikeDyn, PyArrayMethods};
use pyo3::prelude::*;

/// A 1-D input (`float64` after conversion).
pub type In1<'py> = PyArrayLike1<'py, f64, AllowTypeChange>;
/// A 2-D input (`float64` after conversion).
pub type In2<'py> = PyArrayLike2<'py, f64, AllowTypeChange>;
/// An input of any dimension (`float64` after conversion).
pub type InDyn<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// The values of a 1-D input.
pub fn vec1(a: &In1<'_>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

/// Tendon tensions as a Python caller gives them: an array-like (one per tendon, or one for all)
/// or one number for all (a float, an int, a NumPy scalar or 0-d array).
#[derive(FromPyObject)]
pub enum Tensions<'py> {
    Array(In1<'py>),
    Scalar(f64),
}

impl Tensions<'_> {
    /// The values given, one or one per tendon (counted by the caller).
    pub fn values(&self) -> Vec<f64> {
        match self {
            Tensions::Array(a) => vec1(a),
            Tensions::Scalar(x) => vec![*x],
        }
    }
}

/// A 1-D input of length `n` and finite entries (coordinates, velocities) as a vector; else a
/// `GvsromError` naming `name` and the first bad entry.
pub fn dvec(name: &str, a: &In1<'_>, n: usize) -> PyResult<DVector<f64>> {
    let v = a.as_array();
    if v.len() != n {
        return Err(invalid(format!(
            "`{name}` has {} entries, the model has {n} coordinates",
            v.len()
        )));
    }
    finite(name, DVector::from_iterator(n, v.iter().copied()))
}

/// `v` if all its entries are finite; else a `GvsromError` naming `name` and the first bad entry.
pub fn finite(name: &str, v: DVector<f64>) -> PyResult<DVector<f64>> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(v),
        Some(i) => Err(invalid(format!(
            "`{name}[{i}]` = {}: expected a finite number",
            v[i]
        ))),
    }
}

/// A whole-number argument that must not be negative (a count, a size, a seed): pyo3's own
/// conversion to an unsigned type raises a bare `OverflowError` that names neither the argument
/// nor what is accepted.
pub fn unsigned(name: &str, value: i128) -> PyResult<u64> {
    u64::try_from(value).map_err(|_| match value < 0 {
        true => invalid(format!("`{name}` = {value}: expected a whole number ≥ 0")),
        false => invalid(format!(
            "`{name}` = {value}: expected a whole number ≤ {}",
            u64::MAX
        )),
    })
}

/// [`unsigned`] as a size or count.
pub fn size(name: &str, value: i128) -> PyResult<usize> {
    let v = unsigned(name, value)?;
    usize::try_from(v).map_err(|_| invalid(format!("`{name}` = {value}: too large")))
}

/// The rows of a 2-D input, each of length `cols`; else a `GvsromError` naming `name`.
pub fn rows(name: &str, a: &In2<'_>, cols: usize, what: &str) -> PyResult<Vec<Vec<f64>>> {
    let v = a.as_array();
    if v.ncols() != cols {
        return Err(invalid(format!(
            "`{name}` has {} columns, expected {cols} ({what})",
            v.ncols()
        )));
    }
    Ok(v.rows().into_iter().map(|r| r.to_vec()).collect())
}

/// A flat row-major buffer as an array of `shape`.
pub fn shaped<'py, const D: usize>(
    py: Python<'py>,
    flat: Vec<f64>,
    shape: [usize; D],
) -> PyResult<Bound<'py, PyAny>>
where
    [usize; D]: numpy::ndarray::IntoDimension,
{
    Ok(PyArray::from_vec(py, flat).reshape(shape)?.into_any())
}

/// `a` made read-only, as state held by a result object (`Statics`, `Dataset`, `Model`): every
/// access returns the same array, so a write into it would change what the object reports from
/// then on. `a.copy()` gives a writable copy.
pub fn held(a: Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
    let kwargs = pyo3::types::PyDict::new(a.py());
    kwargs.set_item("write", false)?;
    a.call_method("setflags", (), Some(&kwargs))?;
    Ok(a.unbind())
}

/// A 1-D array.
pub fn vector<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyAny> {
    PyArray::from_slice(py, v).into_any()
}

/// A dense matrix as a 2-D array (nalgebra is column-major, NumPy row-major).
pub fn matrix<'py>(py: Python<'py>, m: &DMatrix<f64>) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = m.transpose().as_slice().to_vec();
    shaped(py, flat, [m.nrows(), m.ncols()])
}

/// Row-major flattening of fixed-size rows.
pub fn flat<const N: usize>(rows: &[[f64; N]]) -> Vec<f64> {
    rows.iter().flatten().copied().collect()
}
