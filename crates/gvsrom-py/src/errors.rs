//! Library errors as Python exceptions, with the message the command line prints after `error: `.
//!
//! - `GvsromError(ValueError)`: bad input of any kind (a scenario field, an override, a tension,
//!   an array's shape, a model directory);
//! - `ConvergenceError(GvsromError)`: a statics solve that did not converge, with `iterations`,
//!   `residual_norm` and `load_factor` as attributes (also in the message).

use gvs::solve::statics::StaticsError;
use gvsrom::error::StaticsFailure;
use gvsrom::ScenarioError;
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

create_exception!(
    gvsrom,
    GvsromError,
    PyValueError,
    "Bad input to gvsrom: the message names the field and what is accepted, as the command line prints it."
);
create_exception!(
    gvsrom,
    ConvergenceError,
    GvsromError,
    "A statics solve that did not converge; `iterations`, `residual_norm` and `load_factor` say how far it got."
);

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("GvsromError", py.get_type::<GvsromError>())?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    Ok(())
}

/// A message as a `GvsromError`.
pub fn invalid(message: impl Into<String>) -> PyErr {
    GvsromError::new_err(message.into())
}

/// A scenario error (`{e}`, as `error: {e}` of the command line).
pub fn scenario(e: ScenarioError) -> PyErr {
    GvsromError::new_err(e.to_string())
}

/// Any library error, its causes joined by `: ` as the command line prints them.
pub fn any(e: anyhow::Error) -> PyErr {
    if let Some(f) = e.downcast_ref::<StaticsFailure>() {
        if let StaticsError::NotConverged { .. } = f.error {
            return Python::attach(|py| statics_with_message(py, f, &format!("{e:#}")));
        }
    }
    GvsromError::new_err(format!("{e:#}"))
}

/// An error with its causes joined by `: `, as the command line prints it (anyhow's `{:#}`).
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut message = e.to_string();
    let mut source = e.source();
    while let Some(cause) = source {
        message.push_str(": ");
        message.push_str(&cause.to_string());
        source = cause.source();
    }
    message
}

/// A statics failure: `ConvergenceError` with its diagnostics for a non-convergence, else
/// `GvsromError`.
pub fn statics(py: Python<'_>, f: StaticsFailure) -> PyErr {
    statics_with_message(py, &f, &f.to_string())
}

pub fn statics_with_message(py: Python<'_>, f: &StaticsFailure, message: &str) -> PyErr {
    match f.error {
        StaticsError::NotConverged {
            load_factor,
            iterations,
            residual_norm,
            ..
        } => {
            let err = ConvergenceError::new_err(message.to_string());
            let value = err.value(py);
            // setting attributes on a fresh exception instance cannot fail short of memory
            let _ = value.setattr("iterations", iterations);
            let _ = value.setattr("residual_norm", residual_norm);
            let _ = value.setattr("load_factor", load_factor);
            err
        }
        _ => GvsromError::new_err(message.to_string()),
    }
}
