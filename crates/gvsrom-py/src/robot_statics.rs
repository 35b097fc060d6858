//! `Robot.statics` and `Robot.statics_batch`: the static equilibria of a robot, as `gvsrom
//! statics` and `gvsrom dataset` solve them, with the reduced model attached or not.

use crate::arrays::{self, In2, Tensions};
use crate::errors::{self, invalid, scenario as err};
use crate::interrupt;
use crate::models::Model;
use crate::robot::{Attached, Robot};
use crate::statics::{Statics, StaticsBatch};
use gvsrom::dataset::DEFAULT_CHUNK_SIZE;
use gvsrom::statics::{self, StaticsReport};
use pyo3::prelude::*;
use rayon::prelude::*;
use std::sync::atomic::Ordering;

/// The rows a parallel batch solved, or why it did not finish (a Ctrl-C, a panic caught, the
/// first row that failed, named `U[k]`: a `ConvergenceError` for a solve that did not converge).
fn batch_reports<E: Into<anyhow::Error>>(
    results: Option<Vec<Result<StaticsReport, E>>>,
    caught: Option<PyErr>,
) -> PyResult<Vec<StaticsReport>> {
    if let Some(e) = caught {
        return Err(e);
    }
    let results = results.ok_or_else(|| invalid("statics_batch was stopped before it finished"))?;
    (results.into_iter().enumerate())
        .map(|(k, r)| r.map_err(|e| errors::any(e.into().context(format!("U[{k}]")))))
        .collect()
}

impl Robot {
    /// The equilibrium under `u` with this robot's reduced model as attached, without building
    /// the scenario again: `None` if `u` is not accepted as it is (a bad count or value, a tension
    /// outside the training inputs, a model that extrapolates), where [`Self::rebuilt_with`] gives
    /// the command line's verdict.
    fn solve_attached(&self, py: Python<'_>, u: Option<&[f64]>) -> Option<PyResult<StaticsReport>> {
        let r = self.built.reduced.as_ref()?;
        let u = match u {
            Some(u) => self.built.tensions(u).ok()?,
            None => self.built.u.clone(),
        };
        if !r.covers_tensions(&self.built.u, &u) {
            return None;
        }
        let report = py.detach(|| statics::solve_checked(&self.built, &u));
        Some(report.map_err(errors::any))
    }

    /// The equilibrium under `u` (the scenario's tensions if `None`) with `attached` (else this
    /// robot's model): `gvsrom statics [--tension u] [--model DIR]`; with how the model was used
    /// outside its training (`--extrapolate`'s sentences, the `--json`'s `model_extrapolated`).
    pub(crate) fn solve(
        &self,
        py: Python<'_>,
        u: Option<Vec<f64>>,
        attached: Option<&Attached>,
    ) -> PyResult<(StaticsReport, Vec<String>)> {
        // named as the caller's `u` (a count or a NaN), then checked as the command line checks it
        let u = u.map(|u| self.given_tensions(&u)).transpose()?;
        if u.is_none() && attached.is_none() && self.built.displacement_driven() {
            // the tendons driven by displacement: their tensions are found
            let report = py
                .detach(|| statics::solve_as_built(&self.built))
                .map_err(errors::any)?;
            let extrapolated = crate::robot::model_extrapolated(py, &self.built, &report.u)?;
            return Ok((report, extrapolated));
        }
        match attached.or(self.attached.as_ref()) {
            None => {
                let u = match u {
                    Some(u) => self.built.tensions(&u).map_err(err)?,
                    None => self.built.u.clone(),
                };
                let report = py
                    .detach(|| statics::solve_under(&self.built, &u))
                    .map_err(|f| errors::statics(py, f))?;
                Ok((report, vec![]))
            }
            Some(a) => {
                if attached.is_none() {
                    // answered only where the model is not extrapolating
                    if let Some(report) = self.solve_attached(py, u.as_deref()) {
                        return Ok((report?, vec![]));
                    }
                }
                let built = self.rebuilt_with(py, u.as_deref(), a)?;
                let report = py
                    .detach(|| statics::solve_as_built(&built))
                    .map_err(errors::any)?;
                let extrapolated = crate::robot::model_extrapolated(py, &built, &report.u)?;
                Ok((report, extrapolated))
            }
        }
    }
}

impl Robot {
    /// [`Robot::statics_batch`] with a reduced model attached: each row checked against the
    /// model's training and solved as `statics(U[k])` solves it (from the model's own initial
    /// guess at its tensions), the rows in parallel.
    fn reduced_batch(&self, py: Python<'_>, rows: &[Vec<f64>]) -> PyResult<StaticsBatch> {
        let (Some(r), Some(a)) = (&self.built.reduced, &self.attached) else {
            return Err(invalid("statics_batch: no reduced model attached"));
        };
        let mut extrapolating = vec![];
        for (k, u) in rows.iter().enumerate() {
            if r.covers_tensions(&self.built.u, u) {
                continue;
            }
            match r.extrapolate {
                true => extrapolating.push(k.to_string()),
                // attaching the model to the scenario at `u` gives its verdict and reasons
                false => {
                    if let Err(e) = self.rebuilt_with(py, Some(u), a) {
                        return Err(invalid(format!("U[{k}]: {}", e.value(py))));
                    }
                }
            }
        }
        if !extrapolating.is_empty() {
            crate::robot::warn(
                py,
                &format!(
                    "extrapolating (extrapolate=True): the tensions of rows [{}] lie outside the model's training (statics(U[k]) says how, in its model_extrapolated)",
                    extrapolating.join(", ")
                ),
            )?;
        }
        let built = &self.built;
        let (results, caught) = interrupt::run(py, |flag| {
            rows.par_iter()
                .map(|u| {
                    (flag.load(Ordering::SeqCst) == 0).then(|| statics::solve_checked(built, u))
                })
                .collect::<Option<Vec<_>>>()
        });
        StaticsBatch::new(py, &batch_reports(results, caught)?, built)
    }
}

#[pymethods]
impl Robot {
    /// Static equilibrium under tendon tensions ``u``, as ``gvsrom statics`` solves it (same
    /// numbers as its ``--json``).
    ///
    /// Parameters
    /// ----------
    /// u : array_like of float, optional
    ///     Tensions [N] (negative pulls): one per tendon, or one for all. Default: the scenario's
    ///     drives (its tensions, or its ``displacement`` where a tendon has one).
    /// model : Model or str or os.PathLike, optional
    ///     A reduced model to solve with (``--model``), or its directory, loaded as
    ///     ``load_model(path)`` loads it; default: this robot's.
    /// displacement : array_like of float, optional
    ///     Instead of ``u`` (``--displacement``): the length [m] each tendon's actuator has wound
    ///     in from its rest length (negative pays out), one per tendon or one for all. The
    ///     tensions are found (``Statics.u``); a tendon that would have to push goes slack
    ///     (``Statics.slack``).
    ///
    /// Returns
    /// -------
    /// Statics
    ///     ``q``, the tip pose, the centreline, the strains and the solver statistics.
    ///
    /// Raises
    /// ------
    /// GvsromError
    ///     For tensions of the wrong count, not finite or implausible with the loads; for both
    ///     ``u`` and ``displacement``, or a displacement not reached (with how far each tendon
    ///     got).
    /// ConvergenceError
    ///     If the solve does not converge (with its iterations and residual).
    /// TypeError
    ///     If ``model`` is neither a Model nor a path.
    #[pyo3(signature = (u=None, model=None, displacement=None))]
    fn statics(
        &self,
        py: Python<'_>,
        u: Option<Tensions<'_>>,
        model: Option<&Bound<'_, PyAny>>,
        displacement: Option<Tensions<'_>>,
    ) -> PyResult<Statics> {
        let u = u.map(|a| a.values());
        let attached = (model.map(|m| Model::attached_from(py, m, None))).transpose()?;
        if let Some(d) = displacement {
            if u.is_some() {
                return Err(invalid(
                    "`u` and `displacement` both given: a tendon is driven by its tension or by its displacement (give one)",
                ));
            }
            let mut scenario = self.scenario.clone();
            scenario
                .scenario
                .set_displacements(&d.values())
                .map_err(err)?;
            let attached = attached.as_ref().or(self.attached.as_ref());
            let built = crate::robot::build_with(py, &scenario, attached, false)?;
            let report = py
                .detach(|| statics::solve_as_built(&built))
                .map_err(errors::any)?;
            let extrapolated = crate::robot::model_extrapolated(py, &built, &report.u)?;
            return Statics::new(py, &report, extrapolated);
        }
        let (report, extrapolated) = self.solve(py, u, attached.as_ref())?;
        Statics::new(py, &report, extrapolated)
    }

    /// Static equilibria under many tensions, solved in parallel (all cores, the GIL released).
    ///
    /// As ``gvsrom dataset`` solves a plan of tensions: chunks of 128 consecutive rows in
    /// parallel, each along a chain of nearest neighbours, every solve starting from the nearest
    /// solution of its chunk (the scenario's load ramp from straight if that fails). Row ``k``
    /// equals ``statics(U[k])`` to the solver's tolerance, and the dataset's sample ``k`` of the
    /// same tensions exactly. With ``warm_start=False`` every row is solved from straight, as
    /// ``statics(U[k])`` solves it (the same numbers; 1.2–1.4× the time on IV-A's sweep). With a
    /// reduced model attached (``with_model``) every row is solved as ``statics(U[k])`` solves
    /// it, from the model's own initial guess, and checked against the model's training as it
    /// is (``warm_start`` does not apply).
    ///
    /// Parameters
    /// ----------
    /// U : array_like of float, shape (m, n_actuators)
    ///     One row of tensions [N] per equilibrium. Every tendon is driven by its tension here,
    ///     also one the scenario drives by its displacement (as ``statics(u)`` with ``u`` given).
    /// warm_start : bool
    ///     Start each solve from a neighbouring row's solution (default).
    ///
    /// Returns
    /// -------
    /// StaticsBatch
    ///     The solutions' arrays stacked along a first axis of length m.
    ///
    /// Raises
    /// ------
    /// GvsromError, ConvergenceError
    ///     For the first row that fails, named ``U[k]``, or, with a reduced model attached, whose
    ///     tensions lie outside its training (unless attached with ``extrapolate``: a
    ///     ``UserWarning`` then names those rows).
    #[allow(non_snake_case)]
    #[pyo3(signature = (U, warm_start=true))]
    fn statics_batch(
        &self,
        py: Python<'_>,
        U: In2<'_>,
        warm_start: bool,
    ) -> PyResult<StaticsBatch> {
        let na = self.built.model.n_actuators();
        let rows = arrays::rows("U", &U, na, "one tension per tendon")?;
        let rows = rows
            .iter()
            .enumerate()
            .map(|(k, u)| {
                self.built
                    .tensions(u)
                    .map_err(|e| invalid(format!("U[{k}]: {e}")))
            })
            .collect::<PyResult<Vec<_>>>()?;
        if self.attached.is_some() {
            return self.reduced_batch(py, &rows);
        }
        let built = &self.built;
        let (results, caught) = interrupt::run(py, |flag| {
            let stop =
                || (flag.load(Ordering::SeqCst) != 0).then(|| "interrupted (Ctrl-C)".to_string());
            if warm_start {
                statics::solve_batch(built, &rows, DEFAULT_CHUNK_SIZE, &stop)
            } else {
                rows.par_iter()
                    .map(|u| stop().is_none().then(|| statics::solve_under(built, u)))
                    .collect::<Option<Vec<_>>>()
            }
        });
        StaticsBatch::new(py, &batch_reports(results, caught)?, built)
    }
}
