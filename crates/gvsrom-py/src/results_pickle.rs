//! Pickling results (`multiprocessing`, `concurrent.futures`, `joblib`; `copy`). `Statics` and
//! `StaticsBatch` are values: pickled whole — every field, the arrays as NumPy pickles them (their
//! bytes) — and unpickled equal field by field, the arrays read-only again. `Dataset` and `Model`
//! are directories, pickled as `Robot` pickles its model (`robot_pickle`): the absolute directory
//! and the content it was read with (its manifest's hashes), read again when unpickled
//! (`load_dataset`; `load_model` with the model's `extrapolate`) and refused if the directory was
//! written again in between (one that records no hashes cannot tell, and passes). Nothing in them
//! changes, so `copy.copy` and `copy.deepcopy` return them as they are, without reading the disk.

use crate::arrays::held;
use crate::datasets::{load_dataset, Dataset};
use crate::errors::invalid;
use crate::models::{load_model, Model};
use crate::statics::{Statics, StaticsBatch};
use gvsrom::provenance::DirOrigin;
use numpy::PyUntypedArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::path::{Path, PathBuf};

/// What pickling keeps of a value: its fields by name.
type State<'py> = (Bound<'py, PyDict>,);

/// What pickling keeps of a model: its directory, `extrapolate`, and the content it was read with
/// (JSON of its manifest's hashes), if it records it.
type ModelParts = (PathBuf, bool, Option<String>);

/// What pickling keeps of a dataset: its directory and the content it was read with (JSON of its
/// manifest's hashes).
type DatasetParts = (PathBuf, String);

/// The fields of a pickled value, by name: the dict its `__reduce__` gave.
struct Fields<'a, 'py> {
    class: &'static str,
    state: &'a Bound<'py, PyDict>,
}

impl<'py> Fields<'_, 'py> {
    /// Field `name`; a `GvsromError` naming it if the state lacks it.
    fn item(&self, name: &str) -> PyResult<Bound<'py, PyAny>> {
        self.state
            .get_item(name)?
            .ok_or_else(|| invalid(format!("a pickled {} lacks `{name}`", self.class)))
    }

    /// Field `name` as a `T`; a `GvsromError` naming it if it is missing or of another type.
    fn get<T: FromPyObjectOwned<'py>>(&self, name: &str) -> PyResult<T> {
        let item = self.item(name)?;
        item.extract::<T>().map_err(|e| {
            let e: PyErr = e.into();
            invalid(format!("a pickled {}'s `{name}`: {e}", self.class))
        })
    }

    /// Array field `name`, read-only again.
    fn array(&self, name: &str) -> PyResult<Py<PyAny>> {
        self.held(name, self.item(name)?)
    }

    /// `a`, an array of field `name`, made read-only (an unpickled array, or a deep copy's, is
    /// writable); a `GvsromError` naming the field if it is no NumPy array.
    fn held(&self, name: &str, a: Bound<'py, PyAny>) -> PyResult<Py<PyAny>> {
        if a.cast::<PyUntypedArray>().is_err() {
            return Err(invalid(format!(
                "a pickled {}'s `{name}`: expected a NumPy array",
                self.class
            )));
        }
        held(a)
    }
}

#[pymethods]
impl Statics {
    /// Pickling: every field (`to_dict`), as they are.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, State<'py>)> {
        let restore = slf.get_type().getattr("_restore")?;
        Ok((restore, (slf.get().to_dict(slf.py())?,)))
    }

    /// The equilibrium `__reduce__` describes (for `pickle`; not part of the API).
    #[staticmethod]
    fn _restore(state: &Bound<'_, PyDict>) -> PyResult<Statics> {
        let f = Fields {
            class: "Statics",
            state,
        };
        let paths = (f.item("tendon_paths")?.try_iter()?)
            .map(|p| f.held("tendon_paths", p?))
            .collect::<PyResult<Vec<_>>>()?;
        Ok(Statics {
            scenario: f.get("scenario")?,
            n_dof: f.get("n_dof")?,
            n_points: f.get("n_points")?,
            u: f.array("u")?,
            // pickles written before displacement drives lack these two: no tendon was slack
            slack: match state.get_item("slack")? {
                Some(a) => f.held("slack", a)?,
                None => {
                    let n = f.item("u")?.len()?;
                    held(numpy::PyArray1::from_vec(state.py(), vec![false; n]).into_any())?
                }
            },
            drive_iterations: match state.get_item("drive_iterations")? {
                Some(_) => f.get("drive_iterations")?,
                None => 0,
            },
            q: f.array("q")?,
            tip_position: f.array("tip_position")?,
            tip_rotation: f.array("tip_rotation")?,
            centerline_x: f.array("centerline_x")?,
            centerline: f.array("centerline")?,
            strain_x: f.array("strain_x")?,
            strain: f.array("strain")?,
            strain_reference: f.array("strain_reference")?,
            tendon_paths: PyTuple::new(state.py(), paths)?.into_any().unbind(),
            tendon_lengths: f.array("tendon_lengths")?,
            tendon_rest_lengths: f.array("tendon_rest_lengths")?,
            body_positions: f.array("body_positions")?,
            iterations: f.get("iterations")?,
            load_stages: f.get("load_stages")?,
            residual_evaluations: f.get("residual_evaluations")?,
            jacobian_evaluations: f.get("jacobian_evaluations")?,
            residual_norm: f.get("residual_norm")?,
            divergence: f.get("divergence")?,
            buckled: f.get("buckled")?,
            continued: f.get("continued")?,
            solve_time_s: f.get("solve_time_s")?,
            model_extrapolated: f.get("model_extrapolated")?,
        })
    }
}

impl StaticsBatch {
    /// Its fields by name (all arrays).
    fn fields(&self) -> [(&'static str, &Py<PyAny>); 14] {
        [
            ("u", &self.u),
            ("q", &self.q),
            ("tip_position", &self.tip_position),
            ("tip_rotation", &self.tip_rotation),
            ("centerline_x", &self.centerline_x),
            ("centerline", &self.centerline),
            ("strain_x", &self.strain_x),
            ("strain", &self.strain),
            ("tendon_lengths", &self.tendon_lengths),
            ("iterations", &self.iterations),
            ("residual_norm", &self.residual_norm),
            ("divergence", &self.divergence),
            ("buckled", &self.buckled),
            ("solve_time_s", &self.solve_time_s),
        ]
    }
}

#[pymethods]
impl StaticsBatch {
    /// Pickling: every field (its arrays by name), as they are.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, State<'py>)> {
        let restore = slf.get_type().getattr("_restore")?;
        let state = PyDict::new(slf.py());
        for (name, a) in slf.get().fields() {
            state.set_item(name, a.bind(slf.py()))?;
        }
        Ok((restore, (state,)))
    }

    /// The equilibria `__reduce__` describes (for `pickle`; not part of the API).
    #[staticmethod]
    fn _restore(state: &Bound<'_, PyDict>) -> PyResult<StaticsBatch> {
        let f = Fields {
            class: "StaticsBatch",
            state,
        };
        Ok(StaticsBatch {
            u: f.array("u")?,
            q: f.array("q")?,
            tip_position: f.array("tip_position")?,
            tip_rotation: f.array("tip_rotation")?,
            centerline_x: f.array("centerline_x")?,
            centerline: f.array("centerline")?,
            strain_x: f.array("strain_x")?,
            strain: f.array("strain")?,
            tendon_lengths: f.array("tendon_lengths")?,
            iterations: f.array("iterations")?,
            residual_norm: f.array("residual_norm")?,
            divergence: f.array("divergence")?,
            buckled: f.array("buckled")?,
            solve_time_s: f.array("solve_time_s")?,
        })
    }
}

/// `origin` as pickling keeps it (JSON).
fn origin_json(origin: &DirOrigin) -> PyResult<String> {
    serde_json::to_string(origin).map_err(|e| invalid(format!("cannot pickle the origin: {e}")))
}

/// Refuses the `what` directory `dir` read again on unpickling (by `loader`) if it no longer holds
/// the content the pickled object was read with (`pickled`, JSON; its manifest's hashes, compared
/// as `with_model` compares a model's). `None`: nothing was recorded to compare.
fn unchanged(
    (what, loader): (&str, &str),
    dir: &Path,
    pickled: Option<&str>,
    now: Option<DirOrigin>,
) -> PyResult<()> {
    let Some(pickled) = pickled else {
        return Ok(());
    };
    let pickled: DirOrigin = serde_json::from_str(pickled)
        .map_err(|e| invalid(format!("a pickled {what}'s origin: {e}")))?;
    let same = now
        .is_some_and(|now| now.meta_sha256 == pickled.meta_sha256 && now.sha256 == pickled.sha256);
    match same {
        true => Ok(()),
        false => Err(invalid(format!(
            "{what} `{}`: the directory changed since it was pickled (it was written again): load it again (`{loader}`) to use what it holds now, or unpickle where the directory holds what it held then",
            dir.display()
        ))),
    }
}

/// `e`, an error reading the `what` directory `dir` again on unpickling, saying so.
fn unpickling(py: Python<'_>, what: &str, dir: &Path, e: PyErr) -> PyErr {
    invalid(format!(
        "unpickling the {what} of `{}` (a pickled {what} is read again from its directory, which must be there where it is unpickled): {}",
        dir.display(),
        e.value(py)
    ))
}

#[pymethods]
impl Model {
    /// Pickling: the directory, `extrapolate` and the content it was read with.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, ModelParts)> {
        let me = slf.get();
        let restore = slf.get_type().getattr("_restore")?;
        let origin = me.model.origin().as_ref().map(origin_json).transpose()?;
        Ok((restore, (me.dir.clone(), me.extrapolate, origin)))
    }

    /// The model `__reduce__` describes (for `pickle`; not part of the API).
    #[staticmethod]
    fn _restore(
        py: Python<'_>,
        path: PathBuf,
        extrapolate: bool,
        origin: Option<String>,
    ) -> PyResult<Model> {
        let m = load_model(py, path.clone(), extrapolate)
            .map_err(|e| unpickling(py, "model", &path, e))?;
        let now = m.model.origin();
        unchanged(("model", "load_model"), &path, origin.as_deref(), now)?;
        Ok(m)
    }

    /// The model itself (it holds nothing that changes).
    fn __copy__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    /// The model itself (it holds nothing that changes; `memo` is not needed).
    #[pyo3(signature = (memo))]
    fn __deepcopy__(slf: Py<Self>, memo: &Bound<'_, PyAny>) -> Py<Self> {
        let _ = memo;
        slf
    }
}

#[pymethods]
impl Dataset {
    /// Pickling: the directory and the content it was read with.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, DatasetParts)> {
        let me = slf.get();
        let restore = slf.get_type().getattr("_restore")?;
        let origin = origin_json(&DirOrigin::of_manifest(&me.dir, &me.meta_json))?;
        Ok((restore, (me.dir.clone(), origin)))
    }

    /// The dataset `__reduce__` describes (for `pickle`; not part of the API).
    #[staticmethod]
    fn _restore(py: Python<'_>, path: PathBuf, origin: String) -> PyResult<Dataset> {
        let d = load_dataset(py, path.clone()).map_err(|e| unpickling(py, "dataset", &path, e))?;
        let now = DirOrigin::of_manifest(&d.dir, &d.meta_json);
        unchanged(("dataset", "load_dataset"), &path, Some(&origin), Some(now))?;
        Ok(d)
    }

    /// The dataset itself (it holds nothing that changes).
    fn __copy__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    /// The dataset itself (it holds nothing that changes; `memo` is not needed).
    #[pyo3(signature = (memo))]
    fn __deepcopy__(slf: Py<Self>, memo: &Bound<'_, PyAny>) -> Py<Self> {
        let _ = memo;
        slf
    }
}
