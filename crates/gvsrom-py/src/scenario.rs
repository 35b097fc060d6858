//! `gvsrom.Scenario`: a scenario's source (a preset or TOML text or file) with its `--set`
//! overrides, parsed and validated by the library after every change.

use crate::errors::{invalid, scenario as err};
use gvsrom::presets::{self, Source};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyInt, PyList, PyString, PyTuple};
use std::path::PathBuf;

/// A scenario: a rod, its discretization and strain basis, tendons, loads, solver and output
/// options (the TOML format of `docs/scenario-format.md`).
///
/// Create one with :meth:`Scenario.preset` or :meth:`Scenario.from_toml`, change values with
/// :meth:`set` (the paths of ``gvsrom --set``) and build the model with :meth:`build`.
#[pyclass(module = "gvsrom")]
#[derive(Clone)]
pub struct Scenario {
    pub src: Source,
    /// The `--set` overrides, in order (`path=value`).
    pub overrides: Vec<String>,
    pub scenario: gvsrom::Scenario,
}

impl Scenario {
    fn load(src: Source, overrides: Vec<String>) -> PyResult<Scenario> {
        let scenario = presets::load_from(&src, &overrides).map_err(err)?;
        Ok(Scenario {
            src,
            overrides,
            scenario,
        })
    }
}

/// A Python value as the TOML text of a `--set` value: a `str` as given (read as TOML, a bare word
/// as a string, like the command line), numbers, booleans and sequences of them as TOML.
fn toml_text(value: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(s) = value.cast::<PyString>() {
        return Ok(s.to_str()?.to_string());
    }
    Ok(toml_value(value)?.to_string())
}

fn toml_value(value: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if value.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(value.extract()?));
    }
    if value.is_instance_of::<PyInt>() {
        // TOML integers are 64-bit: a larger int is the number it denotes, as a float, so that the
        // scenario's checks name the field and its range (not a bare `OverflowError`)
        return match (value.extract::<i64>(), value.extract::<f64>()) {
            (Ok(i), _) => Ok(toml::Value::Integer(i)),
            (Err(_), Ok(f)) => Ok(toml::Value::Float(f)),
            (Err(_), Err(_)) => Err(invalid(format!(
                "the int {} is beyond every number a scenario holds (a float's range, ±1.8e308)",
                value.repr()?
            ))),
        };
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(value.extract()?));
    }
    if let Ok(s) = value.cast::<PyString>() {
        return Ok(toml::Value::String(s.to_str()?.to_string()));
    }
    if value.is_instance_of::<PyList>()
        || value.is_instance_of::<PyTuple>()
        || value.hasattr("tolist")?
    {
        // NumPy arrays and scalars through `tolist()`
        let v = if value.hasattr("tolist")? {
            value.call_method0("tolist")?
        } else {
            value.clone()
        };
        if !(v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>()) {
            return toml_value(&v);
        }
        let items = v
            .try_iter()?
            .map(|item| toml_value(&item?))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    Err(invalid(format!(
        "cannot set a value of type `{}`: give a number, a bool, a string (read as TOML) or a list of them",
        value.get_type().name()?
    )))
}

#[pymethods]
impl Scenario {
    /// A built-in preset (see :func:`gvsrom.presets`).
    ///
    /// Parameters
    /// ----------
    /// name : str
    ///     Preset name, e.g. ``"single-tendon"``.
    ///
    /// Raises
    /// ------
    /// GvsromError
    ///     For an unknown name, listing the presets.
    #[staticmethod]
    fn preset(name: &str) -> PyResult<Scenario> {
        if presets::find(name).is_none() {
            return Err(invalid(format!(
                "unknown preset `{name}` (presets: {})",
                presets::names()
            )));
        }
        Scenario::load(presets::source(name).map_err(err)?, vec![])
    }

    /// A scenario from TOML text, or from a file given as a path.
    ///
    /// Parameters
    /// ----------
    /// text_or_path : str or os.PathLike
    ///     A ``pathlib.Path`` (or other path-like) is read as a file; so is a ``str`` of one line
    ///     that names an existing file or ends in ``.toml``. Any other ``str`` is TOML text.
    ///
    /// Raises
    /// ------
    /// GvsromError
    ///     For a syntax error (with line and column), an unknown key or a value of the wrong type
    ///     (naming its path), or a missing file.
    #[staticmethod]
    fn from_toml(text_or_path: &Bound<'_, PyAny>) -> PyResult<Scenario> {
        let src = match text_or_path.cast::<PyString>() {
            Ok(s) => {
                let s = s.to_str()?;
                let one_line = !s.contains('\n');
                // a one-line string naming something on disk is a path (a directory is then
                // refused as one, not parsed as TOML text)
                if one_line && (s.ends_with(".toml") || std::path::Path::new(s).exists()) {
                    file_source(s)?
                } else {
                    Source {
                        origin: gvsrom::presets::TEXT_ORIGIN.into(),
                        default_name: "scenario".into(),
                        text: s.to_string(),
                        preset: false,
                    }
                }
            }
            Err(_) => {
                let path: PathBuf = text_or_path.extract()?;
                file_source(&path.to_string_lossy())?
            }
        };
        Scenario::load(src, vec![])
    }

    /// Sets one value by its TOML path, as ``gvsrom … --set PATH=VALUE`` does.
    ///
    /// Parameters
    /// ----------
    /// path : str
    ///     Dotted key path with 0-based list indices, e.g. ``"tendons.0.tension"``,
    ///     ``"divisions.0.basis.order"``, ``"loads.gravity"``.
    /// value : float, int, bool, str or sequence
    ///     Numbers, booleans and lists are written as TOML; a ``str`` is read as TOML text like a
    ///     ``--set`` value (a bare word is a string).
    ///
    /// Returns
    /// -------
    /// Scenario
    ///     ``self``, changed (for chaining).
    ///
    /// Raises
    /// ------
    /// GvsromError
    ///     If the path is unknown or the value of the wrong type; the scenario is then left
    ///     unchanged. Ranges and the agreement between fields (a basis order and its quadrature,
    ///     a division's length and its tendons) are checked by :meth:`build`, as the command line
    ///     checks all its ``--set`` values together: a change that takes several values can be
    ///     made one ``set`` at a time.
    fn set<'py>(
        mut slf: PyRefMut<'py, Self>,
        path: &str,
        value: &Bound<'py, PyAny>,
    ) -> PyResult<PyRefMut<'py, Self>> {
        let text =
            toml_text(value).map_err(|e| invalid(format!("`{path}`: {}", e.value(value.py()))))?;
        let spec = format!("{path}={text}");
        let mut overrides = slf.overrides.clone();
        overrides.push(spec);
        let next = Scenario::load(slf.src.clone(), overrides)?;
        *slf = next;
        Ok(slf)
    }

    /// The resolved scenario as TOML: every field, defaults filled in, overrides applied
    /// (``gvsrom show`` prints a preset's source instead). Parsing it back gives the same scenario.
    fn to_toml(&self) -> PyResult<String> {
        self.scenario.to_toml().map_err(err)
    }

    /// The scenario's name (the preset name or file stem unless it sets one).
    #[getter]
    fn name(&self) -> String {
        self.scenario.name.clone().unwrap_or_default()
    }

    /// The overrides applied so far, as ``path=value`` strings.
    #[getter]
    fn overrides(&self) -> Vec<String> {
        self.overrides.clone()
    }

    /// The tendon tensions [N], in tendon order.
    #[getter]
    fn tensions(&self) -> Vec<f64> {
        self.scenario.tensions()
    }

    /// Validates the scenario and builds the engine's model: a :class:`Robot`.
    ///
    /// Raises
    /// ------
    /// GvsromError
    ///     Naming the field, its value and the accepted range.
    fn build(slf: PyRef<'_, Self>, py: Python<'_>) -> PyResult<crate::robot::Robot> {
        // a copy, and the borrow released before the build: a `set` from another thread while
        // this one builds changes the scenario, not the robot being built (and is not refused
        // with pyo3's "Already borrowed")
        let scenario = slf.clone();
        drop(slf);
        crate::robot::Robot::new(py, scenario, None)
    }

    /// A copy that later changes do not affect.
    fn copy(&self) -> Scenario {
        self.clone()
    }

    fn __copy__(&self) -> Scenario {
        self.clone()
    }

    /// A copy (a `Scenario` holds no shared state; `memo` is not needed).
    #[pyo3(signature = (memo))]
    fn __deepcopy__(&self, memo: &Bound<'_, PyAny>) -> Scenario {
        let _ = memo;
        self.clone()
    }

    /// Pickling: the source text (a file's as it was read, not the file again), its origin and
    /// the overrides, loaded again as `set` loads them.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Parts)> {
        let me = slf.borrow();
        let restore = slf.get_type().getattr("_restore")?;
        Ok((
            restore,
            (
                me.src.origin.clone(),
                me.src.default_name.clone(),
                me.src.text.clone(),
                me.src.preset,
                me.overrides.clone(),
            ),
        ))
    }

    /// The scenario `__reduce__` describes (for `pickle`; not part of the API).
    #[staticmethod]
    fn _restore(
        origin: String,
        default_name: String,
        text: String,
        preset: bool,
        overrides: Vec<String>,
    ) -> PyResult<Scenario> {
        let src = Source {
            origin,
            default_name,
            text,
            preset,
        };
        Scenario::load(src, overrides)
    }

    fn __repr__(&self) -> String {
        format!(
            "Scenario(name={:?}, source={:?}, overrides={:?})",
            self.name(),
            self.src.origin,
            self.overrides
        )
    }
}

/// What pickling keeps of a scenario: its source's origin, default name, text and whether it is a
/// preset, and the overrides ([`Scenario::_restore`]'s arguments).
type Parts = (String, String, String, bool, Vec<String>);

fn file_source(path: &str) -> PyResult<Source> {
    presets::source(path).map_err(err)
}
