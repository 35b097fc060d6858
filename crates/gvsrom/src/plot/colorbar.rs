//! The colour bar beside a scatter plot: the viridis gradient from the lowest scalar (bottom) to the
//! highest (top), tick labels at round values, and the quantity's name written upwards on the right.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontTransform;

use super::color::{viridis, ColorScale};
use super::layout::{self, OrPlotError};
use super::range::{self, LinearFormat};
use super::theme::Theme;
use super::PlotError;

/// Number of gradient slices; 64 are indistinguishable from a continuous ramp at these sizes.
const SLICES: i32 = 64;

/// The bar's tick values and their labels: round values inside `[lo, hi]` (just the value when the
/// scale is a single value).
fn ticks(scale: &ColorScale) -> Vec<(f64, String)> {
    if scale.hi <= scale.lo {
        return vec![(
            scale.lo,
            LinearFormat::for_ticks(&[scale.lo]).format(scale.lo),
        )];
    }
    let t = range::linear_ticks(&(scale.lo..scale.hi), 6);
    let fmt = LinearFormat::for_ticks(&t);
    t.into_iter().map(|v| (v, fmt.format(v))).collect()
}

/// Width in pixels the colour bar for `scale` and `label` needs: gap, bar, tick labels, label.
pub(crate) fn width<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    scale: &ColorScale,
    label: &str,
    theme: &Theme,
    title: &str,
) -> Result<u32, PlotError> {
    let tick_w = layout::widest(
        area,
        ticks(scale).into_iter().map(|t| t.1),
        &theme.tick_font(),
        title,
    )?;
    let label_w = if label.trim().is_empty() {
        0.0
    } else {
        theme.label_font().font.get_size() * 1.5
    };
    Ok((theme.px(10.0 + 20.0 + 8.0 + 10.0) as f64 + tick_w as f64 + label_w).round() as u32)
}

/// Draws the colour bar into `area` (a strip as wide as [`width`]), spanning the pixel rows
/// `top..bottom` so that it lines up with the plotting area beside it.
pub(crate) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    scale: &ColorScale,
    label: &str,
    (top, bottom): (i32, i32),
    theme: &Theme,
    title: &str,
) -> Result<(), PlotError> {
    let (x0, x1) = (theme.px(10.0), theme.px(30.0));
    let h = (bottom - top).max(1);
    for k in 0..SLICES {
        let ya = bottom - h * k / SLICES;
        let yb = bottom - h * (k + 1) / SLICES;
        let c = viridis((k as f64 + 0.5) / SLICES as f64);
        area.draw(&Rectangle::new([(x0, yb), (x1, ya)], c.filled()))
            .or_plot(title)?;
    }
    area.draw(&Rectangle::new([(x0, top), (x1, bottom)], BLACK.mix(0.5)))
        .or_plot(title)?;

    let font = theme.tick_font().pos(Pos::new(HPos::Left, VPos::Center));
    let tick_len = theme.px(5.0);
    for (v, text) in ticks(scale) {
        let y = bottom - (scale.fraction(v) * h as f64).round() as i32;
        area.draw(&PathElement::new(
            vec![(x1, y), (x1 + tick_len, y)],
            BLACK.mix(0.6),
        ))
        .or_plot(title)?;
        area.draw_text(&text, &font, (x1 + tick_len + theme.px(3.0), y))
            .or_plot(title)?;
    }

    if !label.trim().is_empty() {
        let font = theme.label_font();
        let size = font.font.get_size();
        let font = font
            .transform(FontTransform::Rotate270)
            .pos(Pos::new(HPos::Center, VPos::Center));
        let (w, _) = area.dim_in_pixel();
        let x = w as i32 - (size * 0.75).round() as i32 - theme.px(2.0);
        area.draw_text(label, &font, (x, (top + bottom) / 2))
            .or_plot(title)?;
    }
    Ok(())
}
