//! Colours: conversion to plotters, the default colour of the i-th series, and the viridis scale that
//! maps a scalar to a colour (linear interpolation between nine stops of matplotlib's viridis).

use plotters::style::RGBColor;

use super::validate::plottable;
use super::{palette, Rgb};

/// Colour of points whose scalar is not finite.
pub(crate) const MISSING: RGBColor = RGBColor(170, 170, 170);
/// Colour of points when no scalar colours them.
pub(crate) const PLAIN: RGBColor = RGBColor(40, 40, 40);

impl From<Rgb> for RGBColor {
    fn from(c: Rgb) -> Self {
        RGBColor(c.0, c.1, c.2)
    }
}

/// The colour of series `index`: its own, else `palette::EXTRA[index mod 8]`.
pub(crate) fn series_color(index: usize, own: Option<Rgb>) -> RGBColor {
    own.unwrap_or(palette::EXTRA[index % palette::EXTRA.len()])
        .into()
}

/// Viridis at `t ∈ [0, 1]` (clamped; NaN gives the low end): piecewise-linear through nine stops.
pub(crate) fn viridis(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 9] = [
        (68, 1, 84),
        (71, 44, 122),
        (59, 81, 139),
        (44, 113, 142),
        (33, 144, 141),
        (39, 173, 129),
        (92, 200, 99),
        (170, 220, 50),
        (253, 231, 37),
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let s = t * (STOPS.len() - 1) as f64;
    let i = (s.floor() as usize).min(STOPS.len() - 2);
    let f = s - i as f64;
    let lerp = |a: u8, b: u8| (a as f64 + (b as f64 - a as f64) * f).round() as u8;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    RGBColor(lerp(a.0, b.0), lerp(a.1, b.1), lerp(a.2, b.2))
}

/// A linear map of scalar values `[lo, hi]` onto the viridis scale.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ColorScale {
    pub lo: f64,
    pub hi: f64,
}

impl ColorScale {
    /// The scale spanning the plottable values (finite, |v| ≤ 1e300), or `None` when there are none.
    pub fn from_values(values: &[f64]) -> Option<Self> {
        let mut finite = values.iter().copied().filter(|&v| plottable(v));
        let first = finite.next()?;
        let (lo, hi) = finite.fold((first, first), |(lo, hi), v| (lo.min(v), hi.max(v)));
        Some(Self { lo, hi })
    }

    /// Position of `v` on the scale, `(v − lo)/(hi − lo)`; ½ for a single-valued scale.
    pub fn fraction(&self, v: f64) -> f64 {
        if self.hi > self.lo {
            (v - self.lo) / (self.hi - self.lo)
        } else {
            0.5
        }
    }

    /// The colour of `v` (grey when `v` is not plottable).
    pub fn color(&self, v: f64) -> RGBColor {
        if plottable(v) {
            viridis(self.fraction(v))
        } else {
            MISSING
        }
    }
}
