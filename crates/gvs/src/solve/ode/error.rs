//! Why an integration stops: [`OdeError`], [`OdeFailure`] and the right-hand side's [`RhsError`].

use super::OdeStats;

/// A time in a message as [`crate::error::fmt_value`] writes numbers: `0.16`, `5.06e299` (not
/// 300 digits).
fn shown(t: &f64) -> String {
    crate::error::fmt_value(*t)
}

/// An error reported by the right-hand side (or its Jacobian); it stops the integration.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
#[error("{0}")]
pub struct RhsError(pub String);

/// Why an integration stopped. Except for [`OdeError::Invalid`], every output time before
/// [`OdeError::t_reached`] has been delivered.
#[derive(Debug, Clone, thiserror::Error)]
pub enum OdeError {
    /// The error test (or Newton, for the one-step methods) failed at the smallest step the time
    /// resolution allows; the tolerances in use are named, since too tight ones are a cause.
    #[error("integration stopped at t = {}: step size {h:e} below the minimum {h_min:e} with rtol = {rtol:e}, atol = {atol:e} (tolerances too tight for the problem, or a singularity)", shown(.t))]
    StepSizeUnderflow {
        t: f64,
        h: f64,
        h_min: f64,
        rtol: f64,
        /// The absolute tolerance (the smallest, for per-component tolerances).
        atol: f64,
    },
    /// Newton failed at the smallest step (the adaptive methods: its test asks for a fraction of
    /// `rtol`, so too tight tolerances are a cause, and `tolerances` names them) or after its
    /// retries (the fixed step: `tolerances` is `None`).
    #[error(
        "integration stopped at t = {}: Newton iteration failed to converge repeatedly{}",
        shown(.t),
        tolerances.map_or(String::new(), |(rtol, atol)| format!(
            " with rtol = {rtol:e}, atol = {atol:e} (tolerances too tight for the problem, or a singularity)"
        ))
    )]
    NewtonFailure {
        t: f64,
        /// `(rtol, atol)` of an adaptive method (the smallest `atol` for per-component ones).
        tolerances: Option<(f64, f64)>,
    },
    #[error(
        "integration stopped at t = {}: non-finite value (NaN or infinity) in the solution or the right-hand side",
        shown(.t)
    )]
    NonFinite { t: f64 },
    #[error("integration stopped at t = {}: right-hand side failed: {source}", shown(.t))]
    Rhs { t: f64, source: RhsError },
    #[error("integration stopped at t = {}: maximum number of steps {max_steps} reached", shown(.t))]
    TooManySteps { t: f64, max_steps: usize },
    /// The output callback asked to stop after delivering the sample at `t` (an interrupt, a full
    /// disk), or the system did ([`OdeSystem::stop_requested`](super::OdeSystem::stop_requested)) after the step that reached `t`:
    /// not a failure of the method.
    #[error("integration stopped at t = {}: {reason}", shown(.t))]
    Stopped { t: f64, reason: String },
    #[error("invalid input `{field}`: {message}")]
    Invalid {
        field: &'static str,
        message: String,
    },
}

/// An integration that stopped before its last output time: why, and the work done until then.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{error}")]
pub struct OdeFailure {
    pub error: OdeError,
    /// The counts up to the failure (zero for errors found before the first step: invalid input).
    pub stats: OdeStats,
}

impl OdeFailure {
    /// The outcome of an integration whose work is counted in `stats`.
    pub(super) fn with(
        result: Result<(), OdeError>,
        stats: &OdeStats,
    ) -> Result<OdeStats, OdeFailure> {
        match result {
            Ok(()) => Ok(stats.clone()),
            Err(error) => Err(OdeFailure {
                error,
                stats: stats.clone(),
            }),
        }
    }
}

/// An error found before any step (invalid input, the first output): nothing counted yet.
impl From<OdeError> for OdeFailure {
    fn from(error: OdeError) -> Self {
        OdeFailure {
            error,
            stats: OdeStats::default(),
        }
    }
}

impl OdeError {
    /// The last time the solution reached (the last accepted step), `None` for invalid input.
    pub fn t_reached(&self) -> Option<f64> {
        match self {
            OdeError::StepSizeUnderflow { t, .. }
            | OdeError::NewtonFailure { t, .. }
            | OdeError::NonFinite { t }
            | OdeError::Rhs { t, .. }
            | OdeError::TooManySteps { t, .. }
            | OdeError::Stopped { t, .. } => Some(*t),
            OdeError::Invalid { .. } => None,
        }
    }
}

/// Maps a right-hand-side error to the integration error at the last accepted time `t`.
pub(super) fn rhs_err(t: f64) -> impl Fn(RhsError) -> OdeError {
    move |source| OdeError::Rhs { t, source }
}

pub(super) fn invalid(field: &'static str, message: impl Into<String>) -> OdeError {
    OdeError::Invalid {
        field,
        message: message.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_time_is_shown_as_a_number_not_hundreds_of_digits() {
        // a review's 1e300 s run failed with a 300-digit time in its message
        let e = OdeError::NonFinite { t: 5.062e299 }.to_string();
        assert!(
            e.starts_with("integration stopped at t = 5.062e299: "),
            "{e}"
        );
        let e = OdeError::TooManySteps {
            t: 0.16,
            max_steps: 10,
        }
        .to_string();
        assert!(e.starts_with("integration stopped at t = 0.16: "), "{e}");
    }
}
