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

/// The bar's tick values and their labels: round values inside `[lo, hi]`, plus `lo` and `hi`
/// themselves (one decimal finer) where no round value is within 10 % of the span; just the value
/// when the scale is a single value.
fn ticks(scale: &ColorScale) -> Vec<(f64, String)> {
    let (lo, hi) = (scale.lo, scale.hi);
    if hi <= lo {
        return vec![(lo, LinearFormat::for_ticks(&[lo]).format(lo))];
    }
    let t = range::linear_ticks(&(lo..hi), 6);
    let fmt = LinearFormat::for_ticks(&t);
    let step = match t.as_slice() {
        [a, b, ..] => b - a,
        _ => hi - lo,
    };
    let fine = LinearFormat::for_ticks(&[lo, lo + step / 10.0]);
    let mut out: Vec<(f64, String)> = t.iter().map(|&v| (v, fmt.format(v))).collect();
    for end in [lo, hi] {
        if t.iter().all(|v| (v - end).abs() > 0.1 * (hi - lo)) {
            out.push((end, fine.format(end)));
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

/// Width in pixels the colour bar for `scale` and `label` needs: gap 10, bar 20, ticks 8, tick
/// labels, gap 8, label, and 16 of padding to the next panel (base pixels).
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
        theme.label_font().font.get_size() * 1.2
    };
    Ok((theme.px(10.0 + 20.0 + 8.0 + 8.0 + 16.0) as f64 + tick_w as f64 + label_w).round() as u32)
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
    let ticks = ticks(scale);
    let text_x = x1 + tick_len + theme.px(3.0);
    for (v, text) in &ticks {
        let y = bottom - (scale.fraction(*v) * h as f64).round() as i32;
        area.draw(&PathElement::new(
            vec![(x1, y), (x1 + tick_len, y)],
            BLACK.mix(0.6),
        ))
        .or_plot(title)?;
        area.draw_text(text, &font, (text_x, y)).or_plot(title)?;
    }

    if !label.trim().is_empty() {
        // Written upwards just right of the tick labels.
        let labels = ticks.into_iter().map(|t| t.1);
        let tick_w = layout::widest(area, labels, &theme.tick_font(), title)? as i32;
        let font = theme.label_font();
        let size = font.font.get_size();
        let font = font
            .transform(FontTransform::Rotate270)
            .pos(Pos::new(HPos::Center, VPos::Center));
        let x = text_x + tick_w + theme.px(8.0) + (size * 0.6).round() as i32;
        area.draw_text(label, &font, (x, (top + bottom) / 2))
            .or_plot(title)?;
    }
    Ok(())
}
