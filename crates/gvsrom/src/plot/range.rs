//! Axis ranges from data: the finite extent, a margin, a widened range when all values are equal, log
//! axes that contain at least one power of ten, the equal-aspect expansion, and tick-label formats.

use std::ops::Range;

use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::RangedCoordf64;

use super::validate::plottable;

/// `(min, max)` of the finite values, `None` when there are none.
pub(crate) fn extent(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|&v| plottable(v))
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// A linear axis over `[lo, hi]` with `margin` × span added on each side. A (near-)degenerate extent
/// is widened by ±10 % of its value (±1 around zero). Inputs are plottable (|v| ≤ 1e300), so the
/// span stays finite.
pub(crate) fn linear((lo, hi): (f64, f64), margin: f64) -> Range<f64> {
    let scale = lo.abs().max(hi.abs());
    let span = hi - lo;
    if span <= 1e-12 * scale || span < 1e-280 {
        let c = 0.5 * (lo + hi);
        let half = if c.abs() > 1e-280 { 0.1 * c.abs() } else { 1.0 };
        return (c - half)..(c + half);
    }
    (lo - margin * span)..(hi + margin * span)
}

/// A log axis over positive `[lo, hi]` with `margin` of the decades on each side, extended down to
/// the next power of ten when none lies inside (so the axis always has a labelled tick). The ends
/// stay within 10^±305, normal and finite (plotters' log ticks loop forever on an infinite end).
pub(crate) fn log((lo, hi): (f64, f64), margin: f64) -> Range<f64> {
    let (l0, l1) = (lo.log10(), hi.log10());
    let span = l1 - l0;
    let (mut a, b) = if span < 1e-9 {
        (l0 - 0.5, l1 + 0.5)
    } else {
        (l0 - margin * span, l1 + margin * span)
    };
    if a.ceil() > b {
        a = a.floor();
    }
    let (a, b) = (a.clamp(-305.0, 305.0), b.clamp(-305.0, 305.0));
    10f64.powf(a)..10f64.powf(b.max(a + 0.5))
}

/// Expands `x` or `y` about its centre so that one data unit has the same length in pixels on both
/// axes of a plotting area of `px = (width, height)` pixels.
pub(crate) fn equal_aspect(
    x: Range<f64>,
    y: Range<f64>,
    px: (u32, u32),
) -> (Range<f64>, Range<f64>) {
    let ux = (x.end - x.start) / px.0.max(1) as f64; // data units per pixel
    let uy = (y.end - y.start) / px.1.max(1) as f64;
    let u = ux.max(uy);
    let widen = |r: Range<f64>, n: u32| {
        let c = 0.5 * (r.start + r.end);
        let half = 0.5 * u * n.max(1) as f64;
        (c - half)..(c + half)
    };
    (widen(x, px.0), widen(y, px.1))
}

/// The tick values plotters places on a linear axis given at most `n` labels.
pub(crate) fn linear_ticks(r: &Range<f64>, n: usize) -> Vec<f64> {
    RangedCoordf64::from(r.clone()).key_points(n)
}

/// Formatter for linear tick labels at the spacing of `ticks`: fixed decimals matching the step, or
/// scientific notation for very large or very small magnitudes; "-0" prints as "0".
#[derive(Clone, Copy, Debug)]
pub(crate) struct LinearFormat {
    step: f64,
    decimals: usize,
    scientific: bool,
    mantissa_digits: usize,
}

impl LinearFormat {
    /// The format for the labels `ticks` (their spacing fixes the precision).
    pub fn for_ticks(ticks: &[f64]) -> Self {
        let step = match ticks {
            [a, b, ..] if (b - a).abs() > 0.0 => (b - a).abs(),
            [a, ..] if *a != 0.0 => a.abs(),
            _ => 1.0,
        };
        let mag = ticks.iter().fold(0f64, |m, v| m.max(v.abs()));
        let step_exp = step.log10().floor();
        let decimals = (-step_exp).clamp(0.0, 12.0) as usize;
        let scientific = mag >= 1e5 || (mag > 0.0 && mag < 1e-3);
        let mantissa_digits = if mag > 0.0 {
            (mag.log10().floor() - step_exp).clamp(0.0, 4.0) as usize
        } else {
            0
        };
        Self {
            step,
            decimals,
            scientific,
            mantissa_digits,
        }
    }

    /// The label of tick value `v`.
    pub fn format(&self, v: f64) -> String {
        let v = if v.abs() < 1e-9 * self.step { 0.0 } else { v };
        if v == 0.0 {
            return "0".to_string();
        }
        if self.scientific {
            format!("{:.*e}", self.mantissa_digits, v)
        } else {
            format!("{:.*}", self.decimals, v)
        }
    }
}

/// Formatter for tick labels on a log axis: plain numbers (up to 3 significant digits) when every tick
/// lies in [10⁻³, 10⁴), otherwise all in the form `me±k` ("1e-5", "2.5e6").
#[derive(Clone, Copy, Debug)]
pub(crate) struct LogFormat {
    scientific: bool,
}

impl LogFormat {
    /// The format for the labels `ticks`.
    pub fn for_ticks(ticks: &[f64]) -> Self {
        Self {
            scientific: ticks.iter().any(|v| !(1e-3..1e4).contains(v)),
        }
    }

    /// The label of tick value `v` (empty for a non-positive or non-finite `v`).
    pub fn format(&self, v: f64) -> String {
        if !(v.is_finite() && v > 0.0) {
            return String::new();
        }
        if !self.scientific {
            let decimals = (2.0 - v.log10().floor()).clamp(0.0, 6.0) as usize;
            let s = format!("{:.*}", decimals, v);
            return if s.contains('.') {
                s.trim_end_matches('0').trim_end_matches('.').to_string()
            } else {
                s
            };
        }
        let e = v.log10().floor();
        let m = v / 10f64.powf(e);
        if (m - m.round()).abs() < 1e-6 {
            format!("{}e{}", m.round(), e)
        } else {
            format!("{:.1}e{}", m, e)
        }
    }
}

/// The tick values plotters places on a log axis over `r` given at most `n` labels.
pub(crate) fn log_ticks(r: &Range<f64>, n: usize) -> Vec<f64> {
    use plotters::coord::combinators::{IntoLogRange, LogCoord};
    let coord: LogCoord<f64> = r.clone().log_scale().into();
    coord.key_points(n)
}
