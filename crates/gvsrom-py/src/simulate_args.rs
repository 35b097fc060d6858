//! The arguments of `Robot.simulate` (the options of `gvsrom simulate`) turned into the library's:
//! what drives the run ([`Drive`]: the scenario's tensions, rows `t, u_1, …`, random steps or
//! babbling, or a Python callable, `u(t)` or a controller `u(t, q, q̇)`), where it starts, and
//! the integrator. Every conflict between arguments is refused here, naming both.

use crate::arrays;
use crate::callable::{CallableInput, Kind};
use crate::errors::{invalid, scenario as err};
use gvs::inputs::{Interpolation, Signal};
use gvsrom::simulate::{
    self, ControlLaw, ErrorNormChoice, InputFunction, InputSource, IntegratorChoice, MethodChoice,
};
use pyo3::prelude::*;
use std::sync::Arc;

/// The arguments of [`crate::simulate::run`] (the options of `gvsrom simulate`).
pub struct Args<'a> {
    pub duration: f64,
    pub sample_rate: f64,
    pub input: Option<Bound<'a, PyAny>>,
    pub interpolate: bool,
    pub from_equilibrium: bool,
    /// A given start `(q, q̇)` (`q̇ = 0` if only `q` is given).
    pub q0: Option<Vec<f64>>,
    pub qd0: Option<Vec<f64>>,
    pub method: &'a str,
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    /// A fixed step \[s\]: the fixed-step BDF2 instead of an adaptive method (`--fixed-step`).
    pub fixed_step: Option<f64>,
    /// A CSV file `t, λ` scaling the loads and gravity over time (`--load-schedule`).
    pub load_schedule: Option<std::path::PathBuf>,
    /// Random steps `lo, hi, period` (`--steps`).
    pub steps: Option<Vec<f64>>,
    /// Actuator babbling `lo, hi, hold_min, hold_max` (`--babble`).
    pub babble: Option<Vec<f64>>,
    /// Seed of `steps` and `babble` (`--seed`).
    pub seed: u64,
    /// Highest NDF order (`--max-order`).
    pub max_order: Option<usize>,
    /// The adaptive methods' error test, `componentwise` or `mass` (`--error-norm`).
    pub error_norm: Option<&'a str>,
    /// Generalized-α's spectral radius at infinite frequency (`--rho-inf`).
    pub rho_inf: Option<f64>,
    /// Finite differences for the integrator's Jacobian (`--fd-jacobian`).
    pub fd_jacobian: bool,
    /// A controller `u(t, q, q̇)` called at the control instants, its tensions held between them.
    pub controller: Option<Bound<'a, PyAny>>,
    /// Its calls per second (default: the sample rate).
    pub control_rate: Option<f64>,
    /// A directory to write the trajectory to, as `gvsrom simulate --out` does.
    pub out: Option<std::path::PathBuf>,
    /// Replace an earlier gvsrom output at `out` (`--force`).
    pub force: bool,
}

/// What drives a run: the library's input source, the Python callable behind it (an input
/// function or a controller) if any, and whether the tensions come from a signal rather than the
/// scenario (a reduced model then checks the signal's).
pub struct Drive {
    pub input: InputSource,
    pub callable: Option<Arc<CallableInput>>,
    pub signal: bool,
}

impl Args<'_> {
    /// The input of the run for a robot of `na` tendons (`attached`: with a reduced model).
    pub fn drive(&self, py: Python<'_>, na: usize, attached: bool) -> PyResult<Drive> {
        let a = self;
        let callable = match (&a.input, &a.controller) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "`input` and `controller` both give the tensions: give one",
                ))
            }
            (_, Some(f)) if !f.is_callable() => {
                return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                    "`controller` must be a callable `controller(t, q, qd) -> tensions`, got `{}`",
                    f.repr()?
                )))
            }
            (_, Some(f)) => Some(Arc::new(CallableInput::new(
                f.clone().unbind(),
                Kind::Controller,
                na,
                attached,
            ))),
            (Some(f), None) if f.is_callable() => {
                if a.interpolate {
                    return Err(invalid(
                        "`interpolate` applies to an input of rows, not to a callable `input`",
                    ));
                }
                Some(Arc::new(CallableInput::new(
                    f.clone().unbind(),
                    Kind::Input,
                    na,
                    attached,
                )))
            }
            _ => None,
        };
        if a.control_rate.is_some() && a.controller.is_none() {
            return Err(invalid(
                "`control_rate` is the rate of a `controller`: give one (or leave `control_rate` out)",
            ));
        }
        if a.interpolate && a.controller.is_some() {
            return Err(invalid(
                "`interpolate` applies to an input of rows; a controller's tensions are held",
            ));
        }
        if a.interpolate && a.input.is_none() {
            return Err(invalid(
                "`interpolate` applies to an `input` of rows: give one (without it the tensions are constant)",
            ));
        }
        let random = a.steps.is_some() || a.babble.is_some();
        let given = [&a.steps, &a.babble].iter().filter(|v| v.is_some()).count()
            + usize::from(a.input.is_some() || a.controller.is_some());
        if given > 1 {
            return Err(invalid(
                "`input`, `controller`, `steps` and `babble` each give the tensions: give at most one",
            ));
        }
        random_counts(a.steps.as_deref(), a.babble.as_deref())?;
        let input = match (&a.input, &callable) {
            (None, Some(c)) => InputSource::Feedback {
                law: ControlLaw(c.clone()),
                control_rate: a.control_rate,
            },
            (None, _) if random => InputSource::from_options(
                None,
                false,
                a.steps.as_deref(),
                a.babble.as_deref(),
                a.seed,
            )
            .map_err(err)?,
            (None, _) => InputSource::Constant,
            (Some(_), Some(c)) => InputSource::Function(InputFunction(c.clone())),
            (Some(obj), None) => {
                // a TypeError, as for every array argument, that says what was given
                let rows: arrays::In2<'_> = obj.extract().map_err(|e: PyErr| {
                    pyo3::exceptions::PyTypeError::new_err(format!(
                        "`input` must be rows `t, u_1, …, u_{na}` (1 + {na} columns: a 2-D array) or a callable `u(t)`: {}",
                        e.value(py)
                    ))
                })?;
                let rows = arrays::rows("input", &rows, 1 + na, "t, then one tension per tendon")?;
                arrays::finite_rows("input", &rows, |j| match j {
                    0 => "the time t in s".to_string(),
                    _ => format!("the tension u_{j} of tendon {} in N", j - 1),
                })?;
                InputSource::Rows(Signal {
                    times: rows.iter().map(|r| r[0]).collect(),
                    values: rows.iter().map(|r| r[1..].to_vec()).collect(),
                    interpolation: if a.interpolate {
                        Interpolation::Linear
                    } else {
                        Interpolation::Hold
                    },
                })
            }
        };
        // a reduced model checks a signal's tensions, not the scenario's (`simulate --model`)
        // (from an equilibrium, the scenario's tensions are the start's: checked as attached)
        let signal = random || a.input.is_some() || a.controller.is_some();
        Ok(Drive {
            input,
            callable,
            signal,
        })
    }

    /// The integrator chosen (`--method`, `--rtol`, `--atol`, `--fixed-step`, …).
    pub fn integrator(&self) -> PyResult<IntegratorChoice> {
        let a = self;
        Ok(IntegratorChoice {
            method: method(a.method)?,
            rtol: a.rtol,
            atol: a.atol,
            fixed_step: a.fixed_step,
            max_order: a.max_order,
            error_norm: a.error_norm.map(error_norm).transpose()?,
            rho_inf: a.rho_inf,
            fd_jacobian: a.fd_jacobian,
        })
    }
}

/// `error_norm`: the adaptive methods' error test (`--error-norm`).
pub fn error_norm(name: &str) -> PyResult<ErrorNormChoice> {
    Ok(match name {
        "componentwise" => ErrorNormChoice::Componentwise,
        "mass" => ErrorNormChoice::Mass,
        other => {
            return Err(invalid(format!(
                "invalid `error_norm`: `{other}` (accepted: componentwise, mass)"
            )))
        }
    })
}

/// `steps` and `babble` of 3 and 4 values, named as Python names them (the command line's
/// message counts comma-separated values).
pub fn random_counts(steps: Option<&[f64]>, babble: Option<&[f64]>) -> PyResult<()> {
    for (name, v, names) in [
        ("steps", steps, "[lo, hi, period]"),
        ("babble", babble, "[lo, hi, hold_min, hold_max]"),
    ] {
        let n = names.matches(',').count() + 1;
        if let Some(v) = v.filter(|v| v.len() != n) {
            return Err(invalid(format!(
                "`{name}` takes {n} values {names}, got {}",
                v.len()
            )));
        }
    }
    Ok(())
}

/// `method`: the integrator (`--method`).
pub fn method(name: &str) -> PyResult<MethodChoice> {
    Ok(match name {
        "auto" => MethodChoice::Auto,
        "ndf" => MethodChoice::Ndf,
        "sdirk" => MethodChoice::Sdirk,
        "galpha" => MethodChoice::Galpha,
        other => {
            return Err(invalid(format!(
                "invalid `method`: `{other}` (accepted: auto, ndf, sdirk, galpha)"
            )))
        }
    })
}

/// Where the run starts: `from_equilibrium`, a given state `q0` (`qd0`: zero if not given), or
/// straight at rest.
pub fn start(
    q0: &Option<Vec<f64>>,
    qd0: &Option<Vec<f64>>,
    from_equilibrium: bool,
) -> PyResult<simulate::Start> {
    Ok(match (q0, qd0, from_equilibrium) {
        (Some(_), _, true) => {
            return Err(invalid(
                "`from_equilibrium=True` and `q0` both say where the run starts: give one",
            ))
        }
        (None, Some(_), _) => {
            return Err(invalid(
                "`qd0` given without `q0`: a start state needs its coordinates `q0` (`qd0` defaults to zeros)",
            ))
        }
        (Some(q), qd, false) => simulate::Start::State {
            q: q.clone(),
            qd: qd.clone().unwrap_or_else(|| vec![0.0; q.len()]),
        },
        (None, None, from_equilibrium) => simulate::Start::rest_or_equilibrium(from_equilibrium),
    })
}
