//! Axis ranges from data: the finite extent, a margin, a widened range when all values are equal, log
//! axes and their ticks (1-2-5 within a decade, whole decades over many), the equal-aspect expansion,
//! and tick-label formats.

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

/// A log axis over positive `[lo, hi]` with `margin` of the decades on each side (±½ decade around
/// a single value). The ends stay within 10^±305, normal and finite (plotters' log mapping needs
/// finite logarithms); [`log_ticks`] labels any such range at least thrice.
pub(crate) fn log((lo, hi): (f64, f64), margin: f64) -> Range<f64> {
    let (l0, l1) = (lo.log10(), hi.log10());
    let span = l1 - l0;
    let (a, b) = if span < 1e-9 {
        (l0 - 0.5, l1 + 0.5)
    } else {
        (l0 - margin * span, l1 + margin * span)
    };
    let (a, b) = (a.clamp(-305.0, 305.0), b.clamp(-305.0, 305.0));
    10f64.powf(a)..10f64.powf(b.max(a + 0.1))
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

/// Mantissas of the ticks within one decade, densest first; each set holds the sparser ones.
const MANTISSAS: [&[f64]; 6] = [
    &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    &[1.0, 1.5, 2.0, 3.0, 5.0, 7.0],
    &[1.0, 2.0, 3.0, 5.0],
    &[1.0, 2.0, 5.0],
    &[1.0, 3.0],
    &[1.0],
];

/// The labelled ticks of a log axis over `r`: at least 3 and at most `max(n, 3)` (up to 5 when a
/// sparser choice would leave fewer than 3).
///
/// The densest set that fits is taken, from every mantissa 1…9 of each decade through the 1-2-5
/// sequence to the powers of ten, then every 2nd, 3rd, … power. When even mantissas 1…9 give fewer
/// than 3 ticks (less than about ⅓ decade, where a log axis is nearly linear), the ticks are plain
/// decimals ([`decimal_ticks`]).
pub(crate) fn log_ticks(r: &Range<f64>, n: usize) -> Vec<f64> {
    let max = n.max(3);
    let (lo, hi) = (r.start.min(r.end), r.start.max(r.end));
    if !(lo > 0.0 && hi.is_finite()) {
        return Vec::new();
    }
    let mut denser: Option<Vec<f64>> = None;
    for set in MANTISSAS {
        let ticks = mantissa_ticks(lo, hi, set, 1);
        if (3..=max).contains(&ticks.len()) {
            return ticks;
        }
        if ticks.len() < 3 {
            // the sparsest set of 3 or more (more than `max`), else plain decimals
            return denser.unwrap_or_else(|| decimal_ticks(lo, hi, max));
        }
        denser = Some(ticks);
    }
    // Many decades: every `step`-th power of ten, the smallest step giving at most `max` ticks
    let decades = (hi.log10().ceil() - lo.log10().floor()).max(1.0) as usize;
    let mut best = mantissa_ticks(lo, hi, &[1.0], 1);
    for step in 2..=decades {
        let ticks = mantissa_ticks(lo, hi, &[1.0], step);
        if ticks.len() < 3 {
            break;
        }
        best = ticks;
        if best.len() <= max {
            break;
        }
    }
    best
}

/// `m·10^d` for the mantissas `m` of `set` and every `step`-th exponent `d` (multiples of `step`),
/// those within `[lo, hi]` (up to rounding), ascending.
fn mantissa_ticks(lo: f64, hi: f64, set: &[f64], step: usize) -> Vec<f64> {
    let (d0, d1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let step = step.max(1) as i32;
    let inside = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    // 10^d parsed from its decimal form is the nearest double, unlike powi's products
    let pow = |d: i32| format!("1e{d}").parse::<f64>().unwrap_or(f64::NAN);
    (d0.div_euclid(step) * step..=d1)
        .step_by(step as usize)
        .flat_map(|d| set.iter().map(move |m| m * pow(d)))
        .filter(inside)
        .collect()
}

/// Plain decimal ticks `i·s` in `[lo, hi]` (positive), `s` from 1, 2, 5 × 10^k: the finest step
/// with 3 to `max` ticks, or the coarsest with at least 3 when none fits.
fn decimal_ticks(lo: f64, hi: f64, max: usize) -> Vec<f64> {
    let ticks = |s: f64| -> Vec<f64> {
        let (i0, i1) = (
            (lo / s - 1e-9).ceil() as i64,
            (hi / s + 1e-9).floor() as i64,
        );
        (i0..=i1).map(|i| i as f64 * s).collect()
    };
    let k0 = (hi - lo).log10().ceil() as i32;
    let steps = (0..40).flat_map(|j| [5.0, 2.0, 1.0].map(|m| m * 10f64.powi(k0 - j)));
    let mut best: Option<Vec<f64>> = None;
    for s in steps {
        let t = ticks(s);
        if t.len() > max && best.is_some() {
            break;
        }
        if t.len() >= 3 {
            best = Some(t);
            if best.as_ref().is_some_and(|b| b.len() > max) {
                break;
            }
        }
    }
    best.unwrap_or_default()
}

/// A log₁₀ axis whose labelled ticks are [`log_ticks`] and whose light mesh lines fall on the
/// mantissas 1…9 of each decade when they fit (on the labelled ticks otherwise).
pub(crate) struct LogAxis {
    coord: plotters::coord::combinators::LogCoord<f64>,
    range: Range<f64>,
}

impl LogAxis {
    /// The axis over positive `r`.
    pub fn new(r: Range<f64>) -> Self {
        use plotters::coord::combinators::IntoLogRange;
        Self {
            coord: r.clone().log_scale().into(),
            range: r,
        }
    }
}

impl Ranged for LogAxis {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.coord.map(value, limit)
    }

    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let bold = log_ticks(&self.range, hint.bold_points());
        if hint.max_num_points() <= hint.bold_points() {
            return bold;
        }
        let (lo, hi) = (self.range.start, self.range.end);
        let fine = mantissa_ticks(lo.min(hi), lo.max(hi), MANTISSAS[0], 1);
        if fine.len() <= hint.max_num_points() && fine.len() > bold.len() {
            fine
        } else {
            bold
        }
    }

    fn range(&self) -> Range<f64> {
        self.range.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(lo: f64, hi: f64, n: usize) -> Vec<String> {
        let ticks = log_ticks(&(lo..hi), n);
        let fmt = LogFormat::for_ticks(&ticks);
        ticks.iter().map(|&v| fmt.format(v)).collect()
    }

    #[test]
    fn log_ticks_within_a_decade_follow_the_1_2_5_sequence() {
        // a training loss from 0.3 to 3, one decade: 5 labels fit
        assert_eq!(labels(0.28, 3.3, 5), ["0.3", "0.5", "1", "2", "3"]);
        assert_eq!(labels(0.28, 3.3, 4), ["0.5", "1", "2"]);
        assert_eq!(
            labels(0.28, 3.3, 10),
            ["0.3", "0.4", "0.5", "0.6", "0.7", "0.8", "0.9", "1", "2", "3"]
        );
        // no power of ten inside
        assert_eq!(labels(0.22, 0.85, 4), ["0.3", "0.5", "0.7"]);
        assert_eq!(labels(2.5e-4, 9e-4, 4), ["3e-4", "5e-4", "7e-4"]);
    }

    #[test]
    fn log_ticks_over_a_fraction_of_a_decade_are_plain_decimals() {
        // 1.1 … 1.9 holds no integer mantissa but 1: linear ticks, at least 3
        let ticks = log_ticks(&(1.1..1.9), 4);
        assert!((3..=4).contains(&ticks.len()), "{ticks:?}");
        assert!(ticks.iter().all(|v| (1.1..=1.9).contains(v)), "{ticks:?}");
        assert_eq!(labels(1.1, 1.9, 4), ["1.2", "1.4", "1.6", "1.8"]);
    }

    #[test]
    fn log_ticks_over_many_decades_are_powers_of_ten() {
        assert_eq!(labels(1e-3, 2.0, 5), ["0.001", "0.01", "0.1", "1"]);
        // 12 decades, at most 5 labels: every 3rd power (every 2nd gives 6)
        assert_eq!(labels(3e-9, 2e3, 5), ["1e-6", "1e-3", "1e0", "1e3"]);
        assert_eq!(
            labels(1e-12, 1e12, 6),
            ["1e-10", "1e-5", "1e0", "1e5", "1e10"]
        );
    }

    #[test]
    fn log_ticks_are_never_fewer_than_three() {
        for (lo, hi) in [
            (0.3, 3.0),
            (1.0, 1.05),
            (0.5, 50.0),
            (1e-300, 1e300),
            (7.0, 70.0),
        ] {
            for n in 2..=10 {
                let t = log_ticks(&(lo..hi), n);
                assert!(
                    t.len() >= 3 && t.len() <= n.max(5),
                    "{lo}..{hi}, n = {n}: {t:?}"
                );
                if n >= 5 {
                    assert!(t.len() <= n, "{lo}..{hi}, n = {n}: {t:?}");
                }
                assert!(t.windows(2).all(|w| w[0] < w[1]), "{t:?}");
            }
        }
    }
}
