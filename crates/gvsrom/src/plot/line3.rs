//! 3-D line charts ([`Line3`]) in the box of [`super::axes3`]: each series as a solid or dashed
//! polyline and/or circle markers (gaps at unusable points), and the legend in the upper left.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::axes3::{self, coord, Chart3};
use super::color::series_color;
use super::layout::{self, OrPlotError};
use super::range;
use super::theme::Theme;
use super::validate::{plottable, series_name};
use super::{Line3, PlotError, Series3, SeriesStyle};

/// Contiguous runs of finite points of one series.
fn runs(s: &Series3) -> Vec<Vec<[f64; 3]>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    for p in &s.points {
        if p.iter().all(|&v| plottable(v)) {
            cur.push(*p);
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// Draws `c` into `area`: title, box over the finite points of every series (including `Bounds`
/// ones), the series and the legend.
pub(crate) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    c: &Line3,
    theme: &Theme,
) -> Result<(), PlotError> {
    let title = c.title.as_str();
    let area = layout::titled(area, title, &theme.title_font(), theme)?;
    let runs: Vec<_> = c.series.iter().map(runs).collect();
    let no_data = || PlotError::NoFiniteData {
        title: title.to_string(),
        log_y: false,
    };
    let extent =
        |k: usize| range::extent(runs.iter().flatten().flatten().map(|p| p[k])).ok_or_else(no_data);
    let r = axes3::ranges([extent(0)?, extent(1)?, extent(2)?], c.equal_aspect);
    let (mut chart, _) = axes3::build(&area, &r, theme, title)?;
    for (i, (s, runs)) in c.series.iter().zip(&runs).enumerate() {
        draw_series(&mut chart, i, s, runs, theme).or_plot(title)?;
    }
    axes3::draw_axis_names(&mut chart, &c.labels, &r, theme, title)?;
    let labelled = c
        .series
        .iter()
        .any(|s| s.style != SeriesStyle::Bounds && !s.label.trim().is_empty());
    if labelled {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .margin(theme.px(8.0))
            .legend_area_size(theme.px(40.0))
            .background_style(WHITE.mix(0.92).filled())
            .border_style(BLACK.mix(0.35))
            .label_font(theme.legend_font())
            .draw()
            .or_plot(title)?;
    }
    Ok(())
}

/// Draws series `i` (its runs as lines, dashes and/or markers) and, when labelled, its legend entry.
fn draw_series<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart3<'a, DB>,
    i: usize,
    s: &Series3,
    runs: &[Vec<[f64; 3]>],
    theme: &Theme,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    if s.style == SeriesStyle::Bounds {
        return Ok(());
    }
    let color = series_color(i, s.color);
    let line = color.stroke_width(theme.line_width());
    let dot = color.filled();
    let r = theme.marker_radius();
    let (dash, gap) = (theme.px(9.0), theme.px(5.0));
    for run in runs {
        let pts = run.iter().map(coord);
        match s.style {
            SeriesStyle::Line | SeriesStyle::LineMarkers => {
                chart.draw_series(LineSeries::new(pts, line))?;
            }
            SeriesStyle::Dashed => {
                chart.draw_series(DashedLineSeries::new(pts, dash, gap, line))?;
            }
            SeriesStyle::Markers | SeriesStyle::Bounds => {}
        }
        if matches!(s.style, SeriesStyle::Markers | SeriesStyle::LineMarkers) {
            chart.draw_series(run.iter().map(|p| Circle::new(coord(p), r, dot)))?;
        }
    }
    if s.label.trim().is_empty() {
        return Ok(());
    }
    let anno = chart.draw_series(std::iter::empty::<Circle<(f64, f64, f64), i32>>())?;
    anno.label(series_name(i, &s.label));
    let gw = theme.px(28.0);
    match s.style {
        SeriesStyle::Markers => anno.legend(move |(x, y)| Circle::new((x + gw / 2, y), r, dot)),
        SeriesStyle::LineMarkers => anno.legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (gw, 0)], line)
                + Circle::new((gw / 2, 0), r, dot)
        }),
        _ => anno.legend(move |(x, y)| PathElement::new(vec![(x, y), (x + gw, y)], line)),
    };
    Ok(())
}
