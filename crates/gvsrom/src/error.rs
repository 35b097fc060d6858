//! Errors of scenario loading and building. Every error names the scenario field by its TOML path
//! (`divisions[0].radius_start`), the offending value, and what is accepted.

use gvs::error::fmt_value;
use gvs::solve::statics::StaticsError;
use gvs::ModelError;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum ScenarioError {
    /// The text is not valid TOML.
    #[error("{source_name}: not valid TOML: {message}")]
    Syntax {
        source_name: String,
        message: String,
    },
    /// The TOML is well formed but does not fit the scenario format (unknown key, wrong type,
    /// missing key). `field` is the path of the offending key.
    #[error("`{field}`: {message}")]
    Format { field: String, message: String },
    /// A number outside its accepted range (or not finite).
    #[error("invalid value for `{field}`: {} (expected {expected})", fmt_value(*value))]
    InvalidValue {
        field: String,
        value: f64,
        expected: String,
    },
    /// A structural problem (conflicting or missing keys, counts).
    #[error("invalid `{field}`: {message}")]
    Invalid { field: String, message: String },
    /// A load far beyond the rod's elastic range (see the `plausibility` module); `load` names it by its
    /// scenario path and value.
    #[error("{load} {message}")]
    Implausible { load: String, message: String },
    /// A `--set path=value` override that cannot be applied.
    #[error("--set {spec}: {message}")]
    Override { spec: String, message: String },
    /// Neither a preset name nor an existing file.
    #[error("unknown preset `{name}` and no such file (presets: {available})")]
    UnknownPreset { name: String, available: String },
    /// A path-like argument (ends in `.toml` or has a directory) that does not exist.
    #[error("scenario file `{path}` not found (presets: {available})")]
    NotFound { path: String, available: String },
    #[error("cannot read scenario file `{path}`: {error}")]
    Io { path: String, error: std::io::Error },
    /// Rejected by the engine's own validation (field names follow the engine's naming).
    #[error(transparent)]
    Model(#[from] ModelError),
}

impl ScenarioError {
    pub fn value(field: impl Into<String>, value: f64, expected: impl Into<String>) -> Self {
        ScenarioError::InvalidValue {
            field: field.into(),
            value,
            expected: expected.into(),
        }
    }

    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        ScenarioError::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    /// An [`Invalid`](ScenarioError::Invalid) error about one of several inputs given under the
    /// same name (e.g. `DATASET`), its message prefixed with that input's path; other errors as
    /// they are.
    pub fn naming(self, path: &std::path::Path) -> Self {
        match self {
            ScenarioError::Invalid { field, message } => ScenarioError::Invalid {
                field,
                message: format!("`{}`: {message}", path.display()),
            },
            e => e,
        }
    }
}

/// A statics run that failed: the engine's error and, for a non-convergence, what the scenario says
/// about its cause: `"…; the largest load is tendons[0].tension = -40 N (implied bending ~32 rad);
/// try solver.ramp_steps = 10"`.
#[derive(Debug, Error)]
#[error("{error}{hint}")]
pub struct StaticsFailure {
    /// The engine's error.
    pub error: StaticsError,
    /// Empty, or `"; "`-separated context appended to the engine's message.
    pub hint: String,
}

/// `e` and its causes as one line, `"e: cause: cause…"`, each cause once: a cause whose text
/// already ends the message (an error that shows its `source` in its own text, as
/// `OutputError::Io` shows the I/O error) is not repeated. The front-ends' error line.
pub fn message_chain(e: &dyn std::error::Error) -> String {
    let mut message = e.to_string();
    let mut source = e.source();
    while let Some(cause) = source {
        let text = cause.to_string();
        // shown already when the message ends with it as a whole clause (after ": "), not when a
        // trailing word merely matches
        let shown = message == text || message.ends_with(&format!(": {text}"));
        if !shown {
            message.push_str(": ");
            message.push_str(&text);
        }
        source = cause.source();
    }
    message
}

#[cfg(test)]
mod chain_tests {
    use super::message_chain;
    use std::fmt;

    #[derive(Debug)]
    struct Shows(std::io::Error);
    impl fmt::Display for Shows {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "cannot create `x`: {}", self.0)
        }
    }
    impl std::error::Error for Shows {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            Some(&self.0)
        }
    }

    #[derive(Debug)]
    struct Hides(std::io::Error);
    impl fmt::Display for Hides {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "cannot create `x`")
        }
    }
    impl std::error::Error for Hides {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            Some(&self.0)
        }
    }

    #[test]
    fn a_cause_is_shown_once_whether_or_not_the_error_shows_it() {
        let io = || std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        assert_eq!(
            message_chain(&Shows(io())),
            "cannot create `x`: no such file"
        );
        assert_eq!(
            message_chain(&Hides(io())),
            "cannot create `x`: no such file"
        );
        // a cause equal to the message's last word only is still shown
        let word = || std::io::Error::other("x`");
        assert_eq!(message_chain(&Hides(word())), "cannot create `x`: x`");
    }
}
