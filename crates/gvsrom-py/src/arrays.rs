//! NumPy conversions: array-likes (arrays of any real dtype, lists) in, `float64` arrays out.

use crate::errors::invalid;
use nalgebra::{DMatrix, DVector};
use numpy::ndarray::{Dimension, Ix1, Ix2, IxDyn};
use numpy::{
    AllowTypeChange, PyArray, PyArrayDescrMethods, PyArrayLike, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use std::ops::Deref;

/// An array-like of real numbers of `D` dimensions, `float64` after conversion: a `float64`
/// array as it is, other real dtypes and (nested) lists converted.
///
/// numpy's own conversion casts complex values to real with only NumPy's warning, and refuses a
/// wrong number of dimensions with "dimensionality mismatch: from=2, to=1". This one refuses both
/// with a `TypeError` that says what is accepted and what was given; pyo3 adds the argument's name
/// as the exception's note ("while processing 'q'").
pub struct Real<'py, D: Dimension>(PyArrayLike<'py, f64, D, AllowTypeChange>);

/// A 1-D input (`float64` after conversion).
pub type In1<'py> = Real<'py, Ix1>;
/// A 2-D input (`float64` after conversion).
pub type In2<'py> = Real<'py, Ix2>;
/// An input of any dimension (`float64` after conversion).
pub type InDyn<'py> = Real<'py, IxDyn>;

impl<'py, D: Dimension> Deref for Real<'py, D> {
    type Target = PyArrayLike<'py, f64, D, AllowTypeChange>;
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

/// Kinds of NumPy dtype converted to `float64` without loss of meaning: integers, floats. A
/// boolean is a number to NumPy (`True` is 1) but never a tension, a coordinate or a time here:
/// `[True]` as tensions would pull +1 N.
const REAL_KINDS: &[u8] = b"iuf";

impl<'a, 'py, D: Dimension + 'py> FromPyObject<'a, 'py> for Real<'py, D> {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let what = match D::NDIM {
            Some(1) => "a 1-D array-like of real numbers",
            Some(2) => "a 2-D array-like of real numbers (rows)",
            _ => "an array-like of real numbers",
        };
        Real::extract_as(ob, what)
    }
}

impl<'py, D: Dimension + 'py> Real<'py, D> {
    /// `ob` as an array of `D` dimensions; else a `TypeError` "expected {what}; got …".
    fn extract_as(ob: Borrowed<'_, 'py, PyAny>, what: &str) -> PyResult<Self> {
        // The common case, a float64 array of the right dimension, goes straight through.
        if ob.cast::<PyArray<f64, D>>().is_ok() {
            return Ok(Real(ob.extract()?));
        }
        let py = ob.py();
        let array = numpy_module(py)?
            .call_method1("asarray", (ob,))
            .map_err(|e| {
                PyTypeError::new_err(format!("expected {what}; got {} ({e})", describe(&ob)))
            })?;
        let array = array
            .cast::<PyUntypedArray>()
            .map_err(|_| PyTypeError::new_err(format!("expected {what}; got {}", describe(&ob))))?;
        let kind = array.dtype().kind();
        if !REAL_KINDS.contains(&kind) {
            return Err(PyTypeError::new_err(format!(
                "expected {what}; got values of dtype {}",
                array.dtype()
            )));
        }
        if let Some(n) = D::NDIM {
            if array.ndim() != n {
                return Err(PyTypeError::new_err(format!(
                    "expected {what}; got {}",
                    shape_words(array.shape())
                )));
            }
        }
        Ok(Real(array.as_any().extract()?))
    }
}

/// `numpy`, imported once per interpreter.
fn numpy_module(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    static NUMPY: pyo3::sync::PyOnceLock<Py<PyModule>> = pyo3::sync::PyOnceLock::new();
    NUMPY
        .get_or_try_init(py, || py.import("numpy").map(Bound::unbind))
        .map(|m| m.bind(py))
}

/// "a single number (a 0-D array)", "an array of shape (3, 1)".
fn shape_words(shape: &[usize]) -> String {
    match shape {
        [] => "a single number (a 0-D array)".into(),
        s => format!(
            "an array of shape ({}{})",
            s.iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            if s.len() == 1 { "," } else { "" }
        ),
    }
}

/// The Python type of `ob`, for a message.
fn describe(ob: &Borrowed<'_, '_, PyAny>) -> String {
    ob.get_type()
        .name()
        .map(|n| format!("a `{n}`"))
        .unwrap_or_else(|_| "an object".into())
}

/// The values of a 1-D input.
pub fn vec1(a: &In1<'_>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

/// Whether `ob` is a Python `bool` or a NumPy `bool_`: a number to Python (`True + 1 == 2`), never
/// a tension, an abscissa or a count to gvsrom.
fn is_bool(ob: Borrowed<'_, '_, PyAny>) -> bool {
    ob.is_instance_of::<pyo3::types::PyBool>()
        || ob
            .get_type()
            .name()
            .is_ok_and(|n| n == "bool" || n == "bool_")
        || (ob.cast::<PyUntypedArray>()).is_ok_and(|a| a.ndim() == 0 && a.dtype().kind() == b'b')
}

/// A real-number argument (`#[pyo3(from_py_with = arrays::real)]`: a duration, a period): a
/// `bool` is refused (`simulate(True)` would run for 1 s); pyo3 names the argument in the
/// exception's note.
pub fn real(ob: &Bound<'_, PyAny>) -> PyResult<f64> {
    if is_bool(ob.as_borrowed()) {
        return Err(PyTypeError::new_err("expected a real number; got a `bool`"));
    }
    ob.extract()
}

/// [`real`] of an optional argument (`None` stays `None`).
pub fn real_or_none(ob: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
    match ob.is_none() {
        true => Ok(None),
        false => real(ob).map(Some),
    }
}

/// `ob` as one real number (a float, an int, a NumPy scalar or 0-d array), if it is one. An array
/// of at least one dimension is not, even of one element (NumPy before 2.4 turns that into a number
/// with only a deprecation warning).
fn one_number(ob: Borrowed<'_, '_, PyAny>) -> Option<f64> {
    let is_array = ob.cast::<PyUntypedArray>().is_ok_and(|a| a.ndim() > 0);
    (!is_array).then(|| ob.extract::<f64>().ok()).flatten()
}

/// Abscissae along the rod as a Python caller gives them: one number (a float, an int, a NumPy
/// scalar or 0-d array; a result then drops the axis of the values) or a 1-D array-like of them.
/// A bool is refused (it would read as 0 or 1 m).
pub struct Abscissae {
    pub values: Vec<f64>,
    pub one: bool,
}

impl<'a, 'py> FromPyObject<'a, 'py> for Abscissae {
    type Error = PyErr;

    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        const WHAT: &str = "one abscissa [m] or a 1-D array-like of them";
        if is_bool(ob) {
            return Err(PyTypeError::new_err(format!(
                "expected {WHAT}; got a `bool`"
            )));
        }
        if let Some(x) = one_number(ob) {
            return Ok(Abscissae {
                values: vec![x],
                one: true,
            });
        }
        let a: In1<'py> = Real::extract_as(ob, WHAT)?;
        Ok(Abscissae {
            values: vec1(&a),
            one: false,
        })
    }
}

/// Tendon tensions as a Python caller gives them: an array-like (one per tendon, or one for all)
/// or one number for all (a float, an int, a NumPy scalar or 0-d array).
pub enum Tensions<'py> {
    Array(In1<'py>),
    Scalar(f64),
}

impl<'a, 'py> FromPyObject<'a, 'py> for Tensions<'py> {
    type Error = PyErr;

    /// An array of at least one dimension is an array (NumPy would turn a 1-element one into a
    /// number with a deprecation warning); anything else that is a real number is one; the rest
    /// is read as an array-like, whose error says what is accepted.
    fn extract(ob: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if is_bool(ob) {
            return Err(PyTypeError::new_err(
                "expected tensions [N]: one real number for every tendon, or a 1-D array-like of one per tendon; got a `bool`",
            ));
        }
        if let Some(x) = one_number(ob) {
            return Ok(Tensions::Scalar(x));
        }
        Real::extract_as(
            ob,
            "tensions [N]: one real number for every tendon, or a 1-D array-like of one per tendon",
        )
        .map(Tensions::Array)
    }
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

/// A whole-number argument (`#[pyo3(from_py_with = arrays::whole)]`): pyo3's own conversion
/// raises a bare `OverflowError` "int too big to convert" for an int past `i128`, which says
/// nothing of what is accepted. No count, size, index or seed of gvsrom reaches `u64::MAX`, so
/// this says so; pyo3 names the argument in the exception's note.
///
/// A float of a whole value (`modes(2.0)`) is that number; any other float, and a `bool`, is a
/// `TypeError` saying what is accepted.
pub fn whole(ob: &Bound<'_, PyAny>) -> PyResult<i128> {
    if is_bool(ob.as_borrowed()) {
        return Err(PyTypeError::new_err(
            "expected a whole number; got a `bool`",
        ));
    }
    if ob.is_instance_of::<pyo3::types::PyFloat>() {
        let x: f64 = ob.extract()?;
        return match x.is_finite() && x.fract() == 0.0 && x.abs() <= u64::MAX as f64 {
            true => Ok(x as i128),
            false => Err(PyTypeError::new_err(format!(
                "expected a whole number; got {}",
                ob.repr()?
            ))),
        };
    }
    match ob.extract::<i128>() {
        Err(_) if ob.is_instance_of::<pyo3::types::PyInt>() => Err(invalid(format!(
            "{}: too large, expected a whole number ≤ {}",
            ob.repr()?,
            u64::MAX
        ))),
        other => other,
    }
}

/// A list of strings as an optional argument: one `str` is a list of one, `None` an empty list; a
/// `TypeError` naming `name` for anything else (pyo3's own says "Can't extract `str` to `Vec`" for
/// a `str`, which `Sequence[str]` in the stubs lets through).
pub fn strings(name: &str, ob: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<String>> {
    let Some(ob) = ob.filter(|o| !o.is_none()) else {
        return Ok(vec![]);
    };
    if let Ok(s) = ob.extract::<String>() {
        return Ok(vec![s]);
    }
    ob.extract::<Vec<String>>().map_err(|_| {
        PyTypeError::new_err(format!(
            "`{name}`: expected a str or a list of str; got {}",
            ob.get_type()
                .name()
                .map_or_else(|_| "an object".to_string(), |n| n.to_string())
        ))
    })
}

/// [`whole`] for an optional argument (`None` as it is).
pub fn whole_or_none(ob: &Bound<'_, PyAny>) -> PyResult<Option<i128>> {
    match ob.is_none() {
        true => Ok(None),
        false => whole(ob).map(Some),
    }
}

/// A whole-number argument that must not be negative (a count, a size, a seed).
pub fn unsigned(name: &str, value: i128) -> PyResult<u64> {
    u64::try_from(value).map_err(|_| match value < 0 {
        true => invalid(format!("`{name}` = {value}: expected a whole number ≥ 0")),
        false => invalid(format!(
            "`{name}` = {value}: expected a whole number ≤ {}",
            u64::MAX
        )),
    })
}

/// [`unsigned`] as a size or count whose least accepted value is `min`: a negative value is refused
/// here saying so; the library checks the rest of its range (0 included), naming it.
pub fn size(name: &str, value: i128, min: usize) -> PyResult<usize> {
    if value < 0 {
        return Err(invalid(format!(
            "`{name}` = {value}: expected a whole number ≥ {min}"
        )));
    }
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

/// Every entry of `rows` finite; else a `GvsromError` naming the array's own index
/// (`name[k, j]`) and what column `j` holds (`column(j)`).
pub fn finite_rows(
    name: &str,
    rows: &[Vec<f64>],
    column: impl Fn(usize) -> String,
) -> PyResult<()> {
    for (k, row) in rows.iter().enumerate() {
        if let Some(j) = row.iter().position(|x| !x.is_finite()) {
            return Err(invalid(format!(
                "`{name}[{k}, {j}]` = {}: expected a finite number (column {j} is {})",
                row[j],
                column(j)
            )));
        }
    }
    Ok(())
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
