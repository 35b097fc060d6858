//! The verdict on the estimates: a run's loads are refused, naming the worst, when one goes beyond
//! [`MAX_BENDING`] or [`MAX_STRAIN`]; and the phrase naming the largest load for an error message.

use super::estimates::estimates;
use super::{Subject, MAX_BENDING, MAX_STRAIN};
use crate::error::ScenarioError;

/// Checks the loads and tensions a run will see. `u_max[k]` is the largest |tension| of tendon k over the run,
/// `load_scale_max` the largest |λ| applied to the external loads and gravity (1.0 for statics).
pub fn check<'a>(
    subject: impl Into<Subject<'a>>,
    u_max: &[f64],
    load_scale_max: f64,
) -> Result<(), ScenarioError> {
    let built = subject.into();
    let n_a = built.model.n_actuators();
    if u_max.len() != n_a {
        return Err(ScenarioError::invalid(
            "tendons",
            format!(
                "{} tension bounds given for {n_a} tendons (the plausibility check needs one per tendon)",
                u_max.len()
            ),
        ));
    }
    let worst = estimates(&built, u_max, load_scale_max, true)
        .into_iter()
        .filter(|e| !(e.bending <= MAX_BENDING && e.strain <= MAX_STRAIN))
        .max_by(|a, b| a.severity().total_cmp(&b.severity()));
    match worst {
        None => Ok(()),
        Some(e) => Err(ScenarioError::Implausible {
            load: e.name,
            message: format!(
                "implies a bending of ~{} rad over the rod (accepted <= {MAX_BENDING} rad){}: far beyond the rod's elastic range",
                approx_beyond(e.bending, MAX_BENDING),
                if e.strain > 0.0 || e.strain.is_nan() {
                    format!(
                        " and {} of ~{} (accepted <= {MAX_STRAIN})",
                        e.strain_kind,
                        approx_beyond(e.strain, MAX_STRAIN)
                    )
                } else {
                    String::new()
                }
            ),
        }),
    }
}

/// One phrase naming the load with the largest implied strain, e.g. "the largest load is tendons\[0\].tension = -40 N (implied bending ~12 rad)", or None without loads.
pub fn largest_load<'a>(
    subject: impl Into<Subject<'a>>,
    u: &[f64],
    load_scale: f64,
) -> Option<String> {
    let e = estimates(&subject.into(), u, load_scale, false)
        .into_iter()
        .filter(|e| e.severity() > 0.0)
        .max_by(|a, b| a.severity().total_cmp(&b.severity()))?;
    let strain = if e.strain > 0.0 {
        format!(", {} ~{}", e.strain_kind, approx(e.strain))
    } else {
        String::new()
    };
    Some(format!(
        "the largest load is {} (implied bending ~{} rad{strain})",
        e.name,
        approx(e.bending)
    ))
}

/// About two significant digits: `12`, `0.62`, `3e295`.
/// [`approx`] of a value `v` refused for exceeding `limit`, with as many more digits as it takes
/// to show it above the limit (`1.0` against a limit of 1 reads as `1.004`), up to 12.
fn approx_beyond(v: f64, limit: f64) -> String {
    let shown = approx(v);
    if !(v.is_finite() && v > limit) || shown.parse::<f64>().is_ok_and(|x| x > limit) {
        return shown;
    }
    (3..=12)
        .map(|digits| format!("{:.*}", digits - 1, v))
        .map(|f| {
            f.parse::<f64>()
                .map_or_else(|_| format!("{v}"), gvs::error::fmt_value)
        })
        .find(|f| f.parse::<f64>().is_ok_and(|x| x > limit))
        .unwrap_or_else(|| format!("{v}"))
}

fn approx(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return "0".into();
    }
    let e = v.abs().log10().floor();
    if (-3.0..4.0).contains(&e) {
        let digits = (1.0 - e).max(0.0) as usize;
        format!("{v:.digits$}")
    } else {
        format!("{v:.0e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refused_value_is_shown_above_its_limit() {
        assert_eq!(approx_beyond(1.0042, 1.0), "1.004");
        assert_eq!(approx_beyond(1.00000007, 1.0), "1.0000001");
        assert_eq!(approx_beyond(12.34, 10.0), "12");
        // at or below the limit (not refused for it) it is the plain approximation
        assert_eq!(approx_beyond(0.6234, 1.0), "0.62");
    }

    #[test]
    fn approx_keeps_two_significant_digits() {
        assert_eq!(approx(12.34), "12");
        assert_eq!(approx(0.6234), "0.62");
        assert_eq!(approx(3.7e295), "4e295");
        assert_eq!(approx(f64::INFINITY), "inf");
    }
}
