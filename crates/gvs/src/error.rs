//! Errors of the engine. Every error names the offending field, its value and what is accepted.

use thiserror::Error;

#[derive(Debug, Clone, Error, PartialEq)]
pub enum ModelError {
    /// A numeric input outside its accepted range (or not finite).
    #[error("invalid value for `{field}`: {} (expected {expected})", fmt_value(*value))]
    InvalidValue {
        field: String,
        value: f64,
        expected: String,
    },
    /// A structural inconsistency (sizes, counts, missing items).
    #[error("invalid `{field}`: {message}")]
    Invalid { field: String, message: String },
}

impl ModelError {
    pub fn value(field: impl Into<String>, value: f64, expected: impl Into<String>) -> Self {
        ModelError::InvalidValue {
            field: field.into(),
            value,
            expected: expected.into(),
        }
    }
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        ModelError::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }
}

/// A number for a message: plain decimal when `1e-4 ≤ |v| < 1e15` (or 0), otherwise in exponent form
/// (`1e-300`, not three hundred zeros).
pub fn fmt_value(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e15).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A computed number for a message (a sum of lengths, a product), rounded to 12 significant digits
/// first so its last bit's rounding does not show: `0.7 + 0.2` reads `0.9`, not `0.8999999999999999`.
pub fn fmt_rounded(v: f64) -> String {
    fmt_value(format!("{v:.11e}").parse().unwrap_or(v))
}

/// `v` in exponent form with `digits` decimals, the exponent left out where it is 0: `1.0881e-2`,
/// `1.0878` (not `1.0878e0`), `3.2000e5`.
pub fn fmt_sci(v: f64, digits: usize) -> String {
    let s = format!("{v:.digits$e}");
    match s.strip_suffix("e0") {
        Some(plain) => plain.to_string(),
        None => s,
    }
}

/// Checks `value` is finite and inside `(lo, hi)` with the given openness; names `field` on failure.
pub(crate) fn check_range(
    field: &str,
    value: f64,
    lo: Option<(f64, bool)>,
    hi: Option<(f64, bool)>,
    expected: &str,
) -> Result<f64, ModelError> {
    let ok_lo = match lo {
        Some((l, inclusive)) => value > l || (inclusive && value == l),
        None => true,
    };
    let ok_hi = match hi {
        Some((h, inclusive)) => value < h || (inclusive && value == h),
        None => true,
    };
    if value.is_finite() && ok_lo && ok_hi {
        Ok(value)
    } else {
        Err(ModelError::value(field, value, expected))
    }
}

pub(crate) fn check_positive(field: &str, value: f64, unit: &str) -> Result<f64, ModelError> {
    check_range(
        field,
        value,
        Some((0.0, false)),
        None,
        &format!("a finite number > 0 {unit}"),
    )
}

pub(crate) fn check_finite(field: &str, value: f64) -> Result<f64, ModelError> {
    check_range(field, value, None, None, "a finite number")
}

#[cfg(test)]
mod tests {
    use super::fmt_sci;

    #[test]
    fn fmt_sci_leaves_out_a_zero_exponent_only() {
        assert_eq!(fmt_sci(1.08781, 4), "1.0878");
        assert_eq!(fmt_sci(0.0108812, 4), "1.0881e-2");
        assert_eq!(fmt_sci(320000.0, 4), "3.2000e5");
        assert_eq!(fmt_sci(-2.5, 2), "-2.50");
        assert_eq!(fmt_sci(0.0, 4), "0.0000");
        assert_eq!(fmt_sci(1e10, 1), "1.0e10");
    }
}
