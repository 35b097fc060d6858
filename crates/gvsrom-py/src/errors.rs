//! Library errors as Python exceptions, with the message the command line prints after `error: `,
//! spelled for Python: the command line's flags become the keyword arguments of the same meaning
//! ([`python_spelling`]).
//!
//! - `GvsromError(ValueError)`: bad input of any kind (a scenario field, an override, a tension,
//!   an array's shape, a model directory);
//! - `ConvergenceError(GvsromError)`: a statics solve that did not converge, with `iterations`,
//!   `residual_norm` and `load_factor` as attributes (also in the message);
//! - `IntegrationError(GvsromError)`: a simulation whose integrator failed, or whose callable
//!   input or controller returned a value refused after the start, with the samples it computed
//!   before as the attribute `trajectory`.

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

create_exception!(
    gvsrom,
    IntegrationError,
    GvsromError,
    "A simulation that stopped early: its integrator failed, or a callable `input` or `controller` returned a value refused after the start; `trajectory` holds the samples computed before, as `simulate` returns them. When the run itself failed, `trajectory[\"reason\"]` says why, as the `reason` of a written run's `meta.json`: \"the integration failed\", \"the reduced model left its training region\" or \"the run left the rod's elastic range\"."
);

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("GvsromError", py.get_type::<GvsromError>())?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    m.add("IntegrationError", py.get_type::<IntegrationError>())?;
    m.add_function(wrap_pyfunction!(_python_spelling, m)?)?;
    Ok(())
}

/// [`python_spelling`] of `message`: not part of the API (no stub); the tests call it on messages
/// that are costly to provoke.
#[pyfunction]
fn _python_spelling(message: &str) -> String {
    python_spelling(message)
}

/// A message as a `GvsromError`.
pub fn invalid(message: impl Into<String>) -> PyErr {
    GvsromError::new_err(python_spelling(&message.into()))
}

/// An integrator failure as an `IntegrationError` whose `trajectory` is the samples computed.
pub fn integration(message: &str, trajectory: &Bound<'_, pyo3::types::PyDict>) -> PyErr {
    let err = IntegrationError::new_err(python_spelling(message));
    // setting an attribute on a fresh exception instance cannot fail short of memory
    let _ = err.value(trajectory.py()).setattr("trajectory", trajectory);
    err
}

/// A scenario error (`{e}`, as `error: {e}` of the command line).
pub fn scenario(e: ScenarioError) -> PyErr {
    invalid(e.to_string())
}

/// Any library error, its causes joined by `: ` as the command line prints them.
pub fn any(e: anyhow::Error) -> PyErr {
    if let Some(f) = e.downcast_ref::<StaticsFailure>() {
        if let StaticsError::NotConverged { .. } = f.error {
            return Python::attach(|py| statics_with_message(py, f, &chain(e.as_ref())));
        }
    }
    invalid(chain(e.as_ref()))
}

/// An error with its causes joined by `: `, each once, as the command line prints it
/// ([`gvsrom::error::message_chain`]).
pub fn chain(e: &dyn std::error::Error) -> String {
    gvsrom::error::message_chain(e)
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
            let err = ConvergenceError::new_err(python_spelling(message));
            let value = err.value(py);
            // setting attributes on a fresh exception instance cannot fail short of memory
            let _ = value.setattr("iterations", iterations);
            let _ = value.setattr("residual_norm", residual_norm);
            let _ = value.setattr("load_factor", load_factor);
            err
        }
        _ => invalid(message),
    }
}

/// Flags of the command line whose Python keyword argument has another spelling than the flag's
/// with `-` → `_`.
const RENAMED: [(&str, &str); 6] = [
    ("lambda", "lambda_"),
    ("tension", "u"),
    ("sample-time", "dt"),
    ("output-at", "outputs"),
    ("output-tendon-lengths", "tendon_lengths=True"),
    ("output-tip-orientation", "tip_orientation=True"),
];

/// Flags of the command line that are switches, spelled `name=True` in Python.
const SWITCHES: [&str; 8] = [
    "allow-different",
    "fd-jacobian",
    "force",
    "resume",
    "extrapolate",
    "from-equilibrium",
    "interpolate",
    "quick",
];

/// Flags of the command line that are keyword arguments of the same name in Python.
const SAME: [&str; 46] = [
    "out",
    // no flag of the command line: the library's name for `simulate(control_rate=…)`
    "control-rate",
    "max-order",
    "error-norm",
    "rho-inf",
    "load-schedule",
    "model",
    "set",
    "duration",
    "init",
    "seed",
    "samples",
    "random",
    "sweep",
    "grid",
    "kinetic-weight",
    "rate-weight",
    "input",
    "norm",
    "babble",
    "sample-rate",
    "method",
    "steps",
    "rtol",
    "atol",
    "fixed-step",
    "patience",
    "modes",
    "lr-decay",
    "lr-reductions",
    "loss",
    "lbfgs-iterations",
    "sample-weighting",
    "relative-floor",
    "decoder",
    "count",
    "latent",
    "hidden-layers",
    "chunk-size",
    "learning-rate",
    "epochs",
    "validation-fraction",
    "batch-size",
    "threads",
    "noise",
    "jobs",
];

/// The Python keyword argument for the command line's flag `--{flag}`, if it has one.
fn keyword(flag: &str) -> Option<String> {
    if let Some((_, python)) = RENAMED.iter().find(|(cli, _)| *cli == flag) {
        return Some((*python).to_string());
    }
    if SWITCHES.contains(&flag) {
        return Some(format!("{}=True", flag.replace('-', "_")));
    }
    SAME.contains(&flag).then(|| flag.replace('-', "_"))
}

/// The command line's positional arguments (their value names, upper case) and the Python
/// argument of the same meaning.
const POSITIONAL: [(&str, &str); 6] = [
    ("SCENARIO", "scenario"),
    ("DATASET", "dataset"),
    ("MODEL", "model"),
    // `gvsrom compare REFERENCE RUN`
    ("REFERENCE", "reference"),
    ("RUN", "run"),
    // `gvsrom plot INPUT` is `gvsrom.plot(output, …)`
    ("INPUT", "output"),
];

/// `message` as a Python user reads it: each `--flag` of the command line that is a keyword
/// argument in Python is named as that argument (`--sample-rate` → `sample_rate`, `--lambda` →
/// `lambda_`, `--tension` → `u`, `--force` → `force=True`); other flags stay; a positional
/// argument's value name is the Python argument's (`DATASET` → `dataset`). A command quoted in
/// backticks (`` `gvsrom …` ``) is kept as written: it is meant for a shell.
pub fn python_spelling(message: &str) -> String {
    message
        .split('`')
        .enumerate()
        .map(|(i, part)| match i % 2 == 1 {
            // quoted: a command for the shell, or a path, as written; a flag or a value name
            // standing alone renamed
            true if part.starts_with("gvsrom ") || part.contains(['/', '\\']) => part.to_string(),
            true => match POSITIONAL.iter().find(|(cli, _)| *cli == part) {
                Some((_, python)) => python.to_string(),
                None => flags_as_keywords(part),
            },
            false => positionals_as_arguments(&flags_as_keywords(part)),
        })
        .collect::<Vec<_>>()
        .join("`")
}

/// Every whole word of `text` that is a positional argument's value name ([`POSITIONAL`]),
/// renamed, unless it is part of a path or a file name (next to `/`, `\`, or a `.` inside a
/// name).
fn positionals_as_arguments(text: &str) -> String {
    let is_word_char = |c: char| c.is_alphanumeric() || c == '_' || c == '-';
    let chars: Vec<char> = text.chars().collect();
    let pathlike = |at: Option<&char>, beyond: Option<&char>| match at {
        Some('/' | '\\') => true,
        // `DATASET.toml`, `x.DATASET`: a name; a full stop ends a sentence
        Some('.') => beyond.is_some_and(|c| c.is_alphanumeric()),
        _ => false,
    };
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < chars.len() {
        if !is_word_char(chars[i]) {
            out.push(chars[i]);
            i += 1;
            continue;
        }
        let start = i;
        while i < chars.len() && is_word_char(chars[i]) {
            i += 1;
        }
        let word: String = chars[start..i].iter().collect();
        let before = start.checked_sub(1).map(|k| &chars[k]);
        let before2 = start.checked_sub(2).map(|k| &chars[k]);
        let in_path = pathlike(before, before2) || pathlike(chars.get(i), chars.get(i + 1));
        match POSITIONAL.iter().find(|(cli, _)| *cli == word) {
            Some((_, python)) if !in_path => out.push_str(python),
            _ => out.push_str(&word),
        }
    }
    out
}

/// Every `--flag` of `text` that is a Python keyword argument, renamed ([`keyword`]).
fn flags_as_keywords(text: &str) -> String {
    let is_flag_char = |c: char| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-';
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find("--") {
        let before = rest[..at].chars().next_back();
        let after = &rest[at + 2..];
        let len = after
            .find(|c: char| !is_flag_char(c))
            .unwrap_or(after.len());
        let flag = &after[..len];
        out.push_str(&rest[..at]);
        let starts_word = before.is_none_or(|c| !(c.is_alphanumeric() || c == '-'));
        match keyword(flag).filter(|_| starts_word && !flag.is_empty()) {
            Some(python) => out.push_str(&python),
            None => {
                out.push_str("--");
                out.push_str(flag);
            }
        }
        rest = &after[len..];
    }
    out.push_str(rest);
    out
}
