//! Line charts ([`LineChart`]): a mesh with tick labels and axis descriptions, each series as a solid
//! or dashed line and/or circle markers (gaps at unusable points), and the legend in the upper right.

use std::ops::Range;

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::{CoordTranslate, Shift};
use plotters::prelude::*;

use super::color::series_color;
use super::layout::{self, Frame, OrPlotError};
use super::legend::{self, LegendBox};
use super::range::{self, LinearFormat, LogFormat};
use super::theme::Theme;
use super::validate::{series_name, usable};
use super::{LineChart, PlotError, Series, SeriesStyle};

/// Contiguous runs of usable points of one series; a NaN (or, on a log axis, y ≤ 0) ends a run.
fn runs(s: &Series, log_y: bool) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    for (&x, &y) in s.x.iter().zip(&s.y) {
        if usable(x, y, log_y) {
            cur.push((x, y));
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// Pixel spacing (at 900 × 600) between x tick labels and between y tick labels.
const X_TICK_SPACING: f64 = 110.0;
const Y_TICK_SPACING: f64 = 55.0;

/// Draws `c` into `area`: title strip, axes over the usable data (margins 2 % in x, 5 % in y; equal
/// scales when `equal_aspect`), the series and the legend.
pub(crate) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    c: &LineChart,
    theme: &Theme,
) -> Result<(), PlotError> {
    let title = c.title.as_str();
    let area = layout::titled(area, title, &theme.title_font(), theme)?;
    let runs: Vec<_> = c.series.iter().map(|s| runs(s, c.log_y)).collect();
    let points = || runs.iter().flatten().flatten();
    let no_data = || PlotError::NoFiniteData {
        title: title.to_string(),
        log_y: c.log_y,
    };
    let xe = range::extent(points().map(|p| p.0)).ok_or_else(no_data)?;
    let ye = range::extent(points().map(|p| p.1)).ok_or_else(no_data)?;
    let dim = area.dim_in_pixel();
    let (has_x, has_y) = (!c.x_label.trim().is_empty(), !c.y_label.trim().is_empty());
    let tick_font = theme.tick_font();
    // The plotting height does not depend on the y tick labels' width: fix the y label count first.
    let ny = layout::label_count(
        Frame::new(theme, 0, has_x, has_y).plot_size(dim).1,
        Y_TICK_SPACING,
        theme,
    );

    let xr = range::linear(xe, 0.02);
    if c.log_y {
        let yr = range::log(ye, 0.05);
        let yfmt = LogFormat::for_ticks(&range::log_ticks(&yr, ny));
        let labels = range::log_ticks(&yr, ny)
            .into_iter()
            .map(|v| yfmt.format(v));
        let frame = Frame::new(
            theme,
            layout::widest(&area, labels, &tick_font, title)?,
            has_x,
            has_y,
        );
        let fy = move |v: &f64| yfmt.format(*v);
        return plot(
            &area,
            c,
            theme,
            &runs,
            frame,
            xr,
            range::LogAxis::new(yr),
            ny,
            &fy,
        );
    }

    let yr0 = range::linear(ye, 0.05);
    let frame_for = |yr: &Range<f64>| -> Result<(Frame, LinearFormat), PlotError> {
        let ticks = range::linear_ticks(yr, ny);
        let fmt = LinearFormat::for_ticks(&ticks);
        let w = layout::widest(
            &area,
            ticks.iter().map(|&v| fmt.format(v)),
            &tick_font,
            title,
        )?;
        Ok((Frame::new(theme, w, has_x, has_y), fmt))
    };
    let (mut xr, mut yr) = (xr.clone(), yr0.clone());
    if c.equal_aspect {
        // The y tick labels' width moves the plotting area; two passes settle it.
        for _ in 0..2 {
            let px = frame_for(&yr)?.0.plot_size(dim);
            (xr, yr) = range::equal_aspect(range::linear(xe, 0.02), yr0.clone(), px);
        }
    }
    let (frame, yfmt) = frame_for(&yr)?;
    let fy = move |v: &f64| yfmt.format(*v);
    plot(&area, c, theme, &runs, frame, xr, yr, ny, &fy)
}

/// Builds the chart with x over `xr` and y over `y` (linear or log), draws mesh, series and legend.
#[allow(clippy::too_many_arguments)]
fn plot<DB, Y>(
    area: &DrawingArea<DB, Shift>,
    c: &LineChart,
    theme: &Theme,
    runs: &[Vec<Vec<(f64, f64)>>],
    frame: Frame,
    xr: Range<f64>,
    y: Y,
    ny: usize,
    fy: &dyn Fn(&f64) -> String,
) -> Result<(), PlotError>
where
    DB: DrawingBackend,
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let title = c.title.as_str();
    let nx = layout::label_count(
        frame.plot_size(area.dim_in_pixel()).0,
        X_TICK_SPACING,
        theme,
    );
    let xfmt = LinearFormat::for_ticks(&range::linear_ticks(&xr, nx));
    let fx = move |v: &f64| xfmt.format(*v);
    let mut chart = ChartBuilder::on(area)
        .margin_top(frame.margin_top)
        .margin_right(frame.margin_right)
        .margin_left(frame.margin_left)
        .margin_bottom(frame.margin_bottom)
        .x_label_area_size(frame.x_label_area)
        .y_label_area_size(frame.y_label_area)
        .build_cartesian_2d(xr, y)
        .or_plot(title)?;
    layout::draw_mesh(
        &mut chart,
        theme,
        (nx, ny),
        (&fx, fy),
        (&c.x_label, &c.y_label),
    )
    .or_plot(title)?;

    for (i, (s, runs)) in c.series.iter().zip(runs).enumerate() {
        draw_series(&mut chart, i, s, runs, theme).or_plot(title)?;
    }
    let labels: Vec<String> = c
        .series
        .iter()
        .filter(|s| s.style != SeriesStyle::Bounds && !s.label.trim().is_empty())
        .map(|s| s.label.clone())
        .collect();
    if !labels.is_empty() {
        let lb = LegendBox {
            glyph_area: theme.px(40.0),
            margin: theme.px(8.0),
            inset: theme.px(8.0),
        };
        let drawn: Vec<(&[(f64, f64)], bool)> = c
            .series
            .iter()
            .zip(runs)
            .filter(|(s, _)| s.style != SeriesStyle::Bounds)
            .flat_map(|(s, rs)| {
                rs.iter()
                    .map(move |r| (r.as_slice(), s.style != SeriesStyle::Markers))
            })
            .collect();
        let font = theme.legend_font();
        let position = legend::place(&chart, &labels, &font, lb, &drawn, title)?;
        chart
            .configure_series_labels()
            .position(position)
            .margin(lb.margin)
            .legend_area_size(lb.glyph_area)
            .background_style(WHITE.mix(0.92).filled())
            .border_style(BLACK.mix(0.35))
            .label_font(font)
            .draw()
            .or_plot(title)?;
    }
    Ok(())
}

/// Draws series `i` (its runs as lines, dashes and/or markers) and, when labelled, its legend entry.
fn draw_series<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    i: usize,
    s: &Series,
    runs: &[Vec<(f64, f64)>],
    theme: &Theme,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let color = series_color(i, s.color);
    let line = color.stroke_width(theme.line_width());
    let dot = color.filled();
    let r = theme.marker_radius();
    let (dash, gap) = (theme.px(9.0), theme.px(5.0));
    for run in runs {
        match s.style {
            SeriesStyle::Line | SeriesStyle::LineMarkers => {
                chart.draw_series(LineSeries::new(run.iter().copied(), line))?;
            }
            SeriesStyle::Dashed => {
                chart.draw_series(DashedLineSeries::new(run.iter().copied(), dash, gap, line))?;
            }
            SeriesStyle::Markers | SeriesStyle::Bounds => {}
        }
        if matches!(s.style, SeriesStyle::Markers | SeriesStyle::LineMarkers) {
            chart.draw_series(run.iter().map(|&p| Circle::new(p, r, dot)))?;
        }
    }
    if s.style == SeriesStyle::Bounds || s.label.trim().is_empty() {
        return Ok(());
    }
    // The legend entry hangs on an empty series, so it shows even when the data has no usable point.
    let anno = chart.draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?;
    anno.label(series_name(i, &s.label));
    let gw = theme.px(28.0);
    match s.style {
        SeriesStyle::Line => {
            anno.legend(move |(x, y)| PathElement::new(vec![(x, y), (x + gw, y)], line))
        }
        SeriesStyle::Dashed => anno.legend(move |(x, y)| {
            let seg =
                |a: i32, b: i32| PathElement::new(vec![(a * gw / 28, 0), (b * gw / 28, 0)], line);
            EmptyElement::at((x, y)) + seg(0, 8) + seg(12, 20) + seg(24, 28)
        }),
        SeriesStyle::Markers => anno.legend(move |(x, y)| Circle::new((x + gw / 2, y), r, dot)),
        SeriesStyle::Bounds => anno,
        SeriesStyle::LineMarkers => anno.legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (gw, 0)], line)
                + Circle::new((gw / 2, 0), r, dot)
        }),
    };
    Ok(())
}
